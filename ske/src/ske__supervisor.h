/* SPDX-License-Identifier: Apache-2.0 */
/* The supervisor's private interface: the emulator's state (struct ske, its partitions) and
 * what each of its files offers the others. */
#ifndef SKE__SUPERVISOR_H
#define SKE__SUPERVISOR_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <sys/types.h>
#include <time.h>

#include "canbus/client.h"
#include "hm/hm.h"
#include "ske/plan.h"
#include "ske/ske.h"
#include "ske__fault.h"
#include "ske__stats.h"
#include "ske__trace.h"

/* A partition's process as the supervisor knows it. */
typedef enum {
    SKE_PS_NOT_STARTED,
    SKE_PS_RUNNING, /* alive: waiting for a grant or holding one */
    SKE_PS_STOPPED, /* SIGSTOPped after an overrun; continued at its next window */
    SKE_PS_EXITED,
    SKE_PS_CRASHED,
    SKE_PS_IDLE, /* SET_PARTITION_MODE(IDLE) */
} ske_pstate_t;

/* The memory object of one port. */
typedef struct {
    int fd; /* SKE's read-write descriptor */
    int fd_ro; /* read-only descriptor for destinations, -1 if not needed */
    void *mem;
    size_t size;
} ske_portmem_t;

/* One partition: its configuration, its process, its memory and its figures. */
typedef struct {
    const ske_partition_cfg_t *cfg;
    int index;
    pid_t pid;
    ske_pstate_t state;
    /* How its last process ended on its own, kept whatever the health monitor then did: the
     * statistics report it (an exit with status 0 too). Cleared when a new process starts. */
    bool ended;
    bool ended_by_signal;
    int exit_code; /* exit status, or signal number when ended_by_signal */
    int ctl_fd;
    ske_ctl_t *ctl;
    ske_portmem_t ports[SKE_MAX_PORTS];
    uint32_t grant_seq;
    uint32_t mode_request_seq;
    uint32_t start_condition;
    uint32_t initial_mode;
    clockid_t cpu_clock;
    int64_t cpu_at_yield_ns; /* -1: unknown */
    int64_t cpu_outside_max_ns;
    int64_t cpu_ns;
    uint64_t windows;
    uint64_t overruns;
    uint64_t restarts;
    bool exit_to_judge; /* ended on its own: the health monitor has yet to decide */
    int output_fd; /* its output file, opened by the SKE (output.c); -1: none */
    int64_t output_limit; /* disk_full: the file size its processes may not write past; -1 */
    uint64_t hm_log_lost; /* HM decisions its full health-monitor log port could not take */
} ske_part_t;

/* The emulator: every file of the supervisor is passed it, none keeps state of its own. */
struct ske {
    const ske_module_cfg_t *cfg;
    ske_run_opts_t opts;
    ske_time_mode_t time_mode;
    char node[SKE_NAME_MAX];
    ske_part_t parts[SKE_MAX_PARTITIONS];
    uint64_t chan_messages[SKE_MAX_CHANNELS];
    uint64_t chan_overflows[SKE_MAX_CHANNELS];
    ske_trace_t trace;
    ske_samples_t switch_ns;
    ske_samples_t jitter_ns;
    int64_t epoch_mono_ns;
    int64_t start_mono_ns;
    int64_t frames_done;
    int64_t now_ns; /* module time of the current window start */
    int64_t win_end_ns; /* and its end */
    int cur_partition; /* partition holding the current window, -1 between windows */
    int64_t prev_yield_mono_ns; /* the previous window's yield, for the switch figure */
    uint8_t *xfer; /* one message, for queue transfers */
    pid_t pid; /* the SKE's own process, for its partitions to check */
    int next_schedule; /* schedule index to run from the next major frame */
    int64_t last_switch_ns;
    bool hm_shutdown; /* a module-level SHUTDOWN: the run ends */
    bool hm_reset; /* a module-level RESET: every partition restarts at the next frame */
    uint64_t hm_events;
    volatile sig_atomic_t stop_signal;
    volatile sig_atomic_t child_event;
    char exit_reason[16];
    ske_faults_t faults; /* --fault: injected faults and their bookkeeping */
    ske_switches_t sw; /* --test-switch */
    ske_port_hashes_t hashes; /* --trace-port-hashes: the current window's */
    /* overrun-eats-next-window (emulated mode): until when the last window's partition held
     * the CPU, its window's end plus the CPU time it used past its budget; a window that
     * starts earlier starts late. */
    int64_t cpu_held_until_ns;
    bool on_bus; /* windows wait for the CAN bus's time quanta */
    bool bus_stopped; /* the bus ended the run */
    canbus_client_t bus;
};

/* ---- spawn.c: partition processes ----------------------------------------------------- */

/* Whether the partition's process is there: waiting for a grant, holding one, or stopped. */
bool ske__alive(const ske_part_t *p);
const char *ske__pstate_name(ske_pstate_t s);
/* Starts the partition's process and waits until it has attached and confined itself. */
int ske__spawn(ske_t *s, ske_part_t *p, char *err, size_t errlen);
/* Starts a partition again; a failure leaves it down, traced (start_failed), never fatal. */
int ske__respawn(ske_t *s, ske_part_t *p, int64_t t);
/* Ends the partition's process and everything in its process group, and reaps it. */
void ske__kill_partition(ske_part_t *p);
/* Reaps every partition that ended and records how (partition_exit). */
void ske__reap(ske_t *s);
/* The CPU time the partition's process used, or -1. */
int64_t ske__cpu_now(const ske_part_t *p);

/* ---- portmem.c: port memory ----------------------------------------------------------- */

/* A sealed memory object of `size` bytes mapped at *mem; its descriptor, or a negative errno. */
int ske__memobj(const char *name, size_t size, void **mem);
/* Every port's memory object; a sampling channel's destinations share their source's. */
int ske__setup_ports(ske_t *s, char *err, size_t errlen);
void ske__free_ports(ske_part_t *p);

/* output.c: partitions' output files, and the module's health-monitor log. */
int ske__open_outputs(ske_t *s, char *err, size_t errlen);
void ske__close_outputs(ske_t *s);
void ske__hm_log_publish(ske_t *s, int64_t t, const ske_part_t *about, hm_error_t err,
                         hm_level_t level, hm_action_t action, hm_state_t state, int32_t process,
                         const char *pname, const char *message, size_t mlen);

/* ---- hm_actions.c: health-monitor decisions applied ----------------------------------- */

/* The system state a partition is in, as far as the SKE can tell. */
hm_state_t ske__partition_state(const ske_part_t *p);
/* Writes an hm event's fields; the caller ends it (ske_trace_end). */
void ske__trace_hm_fields(ske_t *s, int64_t t, const ske_part_t *p, hm_error_t err,
                          hm_level_t level, hm_action_t action, hm_state_t state,
                          int32_t process, const char *pname, const char *message, size_t mlen,
                          const char *note);
int ske__hm_handle(ske_t *s, ske_part_t *p, int64_t t, hm_error_t e, hm_state_t state,
                   hm_origin_t origin, int32_t process, const char *pname, const char *msg,
                   size_t mlen, bool fatal, char *err, size_t errlen);
/* The error the partition posted, if any. */
int ske__hm_take_post(ske_t *s, ske_part_t *p, int64_t t, char *err, size_t errlen);
int ske__hm_module_reset(ske_t *s, int64_t t, char *err, size_t errlen);
/* Every partition whose process ended on its own since: PARTITION_EXIT. */
int ske__judge_exits(ske_t *s, int64_t t, char *err, size_t errlen);

/* ---- window.c: one window ------------------------------------------------------------- */

int ske__run_window(ske_t *s, const ske_slot_t *slot, char *err, size_t errlen);
/* Copies the partition's events into the trace. */
void ske__drain_events(ske_t *s, ske_part_t *p, int64_t win_start, int64_t win_end);

/* ---- modes.c: operating modes and module schedules ------------------------------------ */

const char *ske__mode_name(uint32_t m);
/* The SKE's own record of a mode change it made (power-on, IDLE, restart). */
void ske__trace_mode(ske_t *s, ske_part_t *p, int64_t t, uint32_t mode, uint32_t from,
                     const char *why);
int ske__handle_mode_request(ske_t *s, ske_part_t *p, int64_t t, char *err, size_t errlen);
void ske__take_schedule_request(ske_t *s, ske_part_t *p, int64_t t);
void ske__switch_schedule(ske_t *s, ske_slot_t *slot, int to);

/* ---- fault.c: injected faults (--fault) ----------------------------------------------- */

/* Parses and checks every spec against the module; SKE_E_CONFIG with one line in err. */
int ske__faults_parse(ske_faults_t *fs, const ske_module_cfg_t *m, const char *const *specs,
                      int n, char *err, size_t errlen);
/* Arms the partition's faults in its control block, with the bookkeeping so far. */
void ske__faults_fill_ctl(const ske_t *s, const ske_part_t *p);
/* A fault event the partition recorded (slot, ske_fault_state_t, what it did): traced, the
 * bookkeeping updated. False if the slot or state is not one of the partition's. */
bool ske__fault_event(ske_t *s, ske_part_t *p, int64_t t, int32_t slot, int32_t state,
                      const char *text, size_t len);
/* At a window of a partition that is not running: the spells that started are refused. */
void ske__faults_window_start(ske_t *s, ske_part_t *p, int64_t t);
/* At each window of a partition: a full disk under its output file (disk_full) that
 * starts or ends. */
void ske__faults_output(ske_t *s, ske_part_t *p, int64_t t);
/* At a major frame's start: a module reset due. */
void ske__faults_frame_start(ske_t *s, int64_t t, int64_t frame);

/* ---- switches.c: test switches (--test-switch) ---------------------------------------- */

int ske__switches_parse(ske_switches_t *sw, const ske_module_cfg_t *m, const char *const *given,
                        int n, char *err, size_t errlen);
/* One test_switch event per switch, at module start. */
void ske__switches_trace(ske_t *s);
/* Before a window: a corrupt-port due. */
void ske__switches_window_start(ske_t *s, int64_t t);
/* hm-action: the partition action that replaces the tables' for this partition, if any. */
bool ske__switch_hm_action(const ske_t *s, const ske_part_t *p, hm_action_t *action);

/* ---- port_hash.c: port hashes (--trace-port-hashes) ----------------------------------- */

void ske__port_hash_grant(ske_t *s, ske_part_t *p);
void ske__port_hash_queue(ske_t *s, int k, const void *msg, uint32_t len);
void ske__port_hash_end(ske_t *s, ske_part_t *p, int64_t t);

/* ---- stats_out.c: the module_start event and the statistics file ---------------------- */

void ske__trace_module_start(ske_t *s);
/* 0, or a negative errno. */
int ske__write_stats(ske_t *s, double wall_s);

#endif /* SKE__SUPERVISOR_H */
