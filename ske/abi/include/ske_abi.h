/* SPDX-License-Identifier: Apache-2.0 */
/* The contract between the Separation Kernel Emulator and a partition's APEX library:
 * the control block each partition shares with the SKE, and the layout of port memory. */
#ifndef SKE_ABI_H
#define SKE_ABI_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <time.h>

#define SKE_ABI_MAGIC 0x53414d49u /* "IMAS" */
#define SKE_ABI_VERSION 6u

#define SKE_NAME_MAX 32 /* names carry at most 31 characters + NUL (ARINC allows 30) */
#define SKE_MAX_PORTS 64 /* per partition */
#define SKE_EVENT_RING 256 /* partition → SKE trace events per window, power of two */
#define SKE_EVENT_TEXT 128
#define SKE_HM_STATES 4 /* hm_state_t values */
#define SKE_HM_ERRORS 11 /* hm_error_t values, 0 unused */
#define SKE_SCHEDULES 8 /* module schedules (ARINC 653 Part 2) */
#define SKE_FAULT_SLOTS 8 /* injected faults armed per partition (ima-ske --fault) */
#define SKE_FAULT_ID_MAX 16 /* a fault id with its NUL (faultinject's FI_ID_MAX) */

/* Sandbox flags (ske_ctl_t.sandbox_flags); the policy itself is in ske_sandbox.h. */
#define SKE_SANDBOX_IO (1u << 0) /* a system partition: it may open files and sockets */

/* Environment variable naming the control block's file descriptor in a partition. */
#define SKE_ENV_CTL_FD "IMA_SKE_CTL_FD"
/* Environment variable naming the descriptor of the partition's output file (ima:Linux
 * OutputFile), which the SKE opened for it: the only file it may write. */
#define SKE_ENV_OUTPUT_FD "IMA_OUTPUT_FD"

#ifdef IMA_COVERAGE
/* Coverage builds only (cmake -DIMA_COVERAGE=ON): the signal by which ima-ske asks a
 * partition's process to write its gcov counters and exit, before it kills it (a SIGKILL
 * alone would lose them). Its number, 12 on Linux: SIGUSR2. */
#define SKE_COVERAGE_SIGNAL 12
#endif

typedef enum {
    SKE_TIME_EMULATED = 0,
    SKE_TIME_REALTIME = 1,
} ske_time_mode_t;

typedef enum {
    SKE_PORT_SAMPLING = 1,
    SKE_PORT_QUEUING = 2,
} ske_port_kind_t;

typedef enum {
    SKE_DIR_SOURCE = 0, /* same values as the APEX PORT_DIRECTION_TYPE */
    SKE_DIR_DESTINATION = 1,
} ske_port_dir_t;

/* Operating modes, same values as APEX OPERATING_MODE_TYPE. */
enum { SKE_MODE_IDLE = 0, SKE_MODE_COLD_START = 1, SKE_MODE_WARM_START = 2, SKE_MODE_NORMAL = 3 };

/* Partition → SKE trace events. The SKE validates every field: the ring lives in memory the
 * partition can write, so its content is untrusted. */
typedef enum {
    SKE_EV_MODE = 1, /* a = new mode, b = previous mode */
    SKE_EV_PORT_VALIDITY = 2, /* a = port index, b = new validity (0 invalid, 1 valid) */
    SKE_EV_APP_MESSAGE = 3, /* a = process id (0 = initialisation), text = message */
    SKE_EV_PROCESS = 4, /* a = process id, b = ske_proc_event_t, text = process name */
    SKE_EV_HM = 5, /* process-level error: a = hm_error_t, b = failed process id,
                      text = ske_hm_text_t (process name, then the message) */
    SKE_EV_FAULT = 6, /* an injected fault: a = fault slot, b = ske_fault_state_t,
                         text = what was done */
} ske_event_kind_t;

typedef enum {
    SKE_PROC_EV_START = 1,
    SKE_PROC_EV_STOP = 2,
} ske_proc_event_t;

typedef struct {
    int64_t t_ns;
    uint32_t kind;
    int32_t a;
    int32_t b;
    uint32_t len; /* bytes used in text */
    char text[SKE_EVENT_TEXT];
} ske_event_t;

/* The classes of injected faults a partition commits itself (faultinject's catalogue): the
 * APEX library's fault hook makes the partition misbehave for real, so that what detects
 * the misbehaviour (a signal, the SKE's overrun detection, the deadline check, the health
 * monitor) detects a real event. */
typedef enum {
    SKE_FAULT_NONE = 0,
    SKE_FAULT_PARTITION_CRASH = 1,
    SKE_FAULT_PARTITION_HANG = 2,
    SKE_FAULT_CPU_OVERRUN = 3,
    SKE_FAULT_MEMORY_VIOLATION = 4,
    SKE_FAULT_NUMERIC_ERROR = 5,
    SKE_FAULT_STACK_OVERFLOW = 6,
    SKE_FAULT_ILLEGAL_REQUEST = 7,
    SKE_FAULT_APPLICATION_ERROR = 8,
    SKE_FAULT_DEADLINE_MISS = 9,
    SKE_FAULT_MEMORY_EXHAUSTION = 10,
    SKE_FAULT_CORRUPT_OUTPUT = 11,
    SKE_FAULT_STUCK_OUTPUT = 12,
    SKE_FAULT_QUEUING_FLOOD = 13,
    SKE_FAULT_FOREIGN_PORT_WRITE = 14,
    SKE_FAULT_CLASSES = 15,
} ske_fault_class_t;

/* What became of a fault (SKE_EV_FAULT; the trace's `state`). */
typedef enum {
    SKE_FAULT_APPLIED = 1,
    SKE_FAULT_CLEARED = 2, /* a state fault whose spell ended */
    SKE_FAULT_REFUSED = 3, /* its spell started but it could not be committed */
} ske_fault_state_t;

/* One fault armed for the partition. The SKE writes the whole slot before exec; the
 * bookkeeping (done_spell, active) is the SKE's record of what happened to the fault so far,
 * kept across restarts of the partition, which learns from it what not to do again. */
typedef struct {
    uint32_t cls; /* ske_fault_class_t */
    uint32_t duration; /* 0 permanent, 1 transient, 2 intermittent (faultinject's fi_duration_t) */
    int64_t at_ns;
    int64_t until_ns; /* INT64_MAX: none */
    int64_t period_ns; /* intermittent */
    int64_t on_ns; /* intermittent */
    int64_t value_ns; /* cpu_overrun: the CPU time to spin */
    int32_t port; /* index in ports[], -1: none */
    uint32_t active; /* a state fault applied in spell done_spell and not cleared yet */
    int64_t done_spell; /* the last spell the fault was applied or refused in, -1: none */
    char process[SKE_NAME_MAX]; /* the process that commits it; "": whichever runs */
    char fid[SKE_FAULT_ID_MAX];
} ske_fault_slot_t;

/* One health-monitor decision of the module, as the SKE writes it into the destination
 * queuing port a partition names as its module's health-monitor log (ima:Linux
 * HealthMonitorLogPort): every decision taken at partition or module level, whichever
 * partition it is about. */
typedef struct {
    int64_t t_ns; /* module time of the decision */
    char partition[SKE_NAME_MAX]; /* the partition the error is about */
    char process[SKE_NAME_MAX]; /* the failed process, "" for none */
    uint32_t error; /* hm_error_t */
    uint32_t level; /* hm_level_t */
    uint32_t action; /* hm_action_t */
    uint32_t state; /* hm_state_t */
    int32_t process_id;
    int32_t error_code; /* APEX ERROR_CODE_TYPE */
    uint32_t len; /* bytes used in message */
    char message[SKE_EVENT_TEXT];
    uint32_t pad;
} ske_hm_log_t;

/* One of the partition's own ports. The SKE fills it before exec; `fd` is the partition's
 * descriptor of the port memory (read-only for destination ports). */
typedef struct {
    char name[SKE_NAME_MAX];
    uint32_t kind; /* ske_port_kind_t */
    uint32_t dir; /* ske_port_dir_t */
    uint32_t max_size; /* bytes */
    uint32_t max_nb; /* queuing: capacity of this port's queue */
    int64_t refresh_ns; /* sampling: refresh period */
    int32_t fd;
    uint32_t map_size; /* bytes to map */
    uint32_t channel; /* channel identifier, 0 if unconnected */
    /* Destination queuing ports: the consumer side of the queue, written by the partition. */
    _Atomic uint32_t rx_tail;
    _Atomic uint32_t overflow_ack;
} ske_port_desc_t;

/* The control block. Written by the SKE before exec (identity, schedule, ports) and then
 * used for the grant/yield hand-over:
 *   SKE grants:        win_start/win_end set, then ++grant_seq and a futex wake.
 *   partition yields:  yield_seq = grant_seq it observed, then a futex wake; it then waits
 *                      for grant_seq to change.
 * Everything the partition writes is untrusted by the SKE. */
typedef struct {
    uint32_t magic;
    uint32_t version;
    uint32_t ctl_size; /* sizeof(ske_ctl_t) as the SKE was built: catches a stale partition */
    int32_t partition_id;
    char partition_name[SKE_NAME_MAX];
    char node[SKE_NAME_MAX];
    uint32_t time_mode; /* ske_time_mode_t */
    uint32_t system_partition;
    int64_t epoch_mono_ns; /* real-time mode: CLOCK_MONOTONIC of module time 0 */
    int64_t period_ns; /* partition period */
    int64_t duration_ns; /* window time per partition period */
    int64_t period_anchor_ns; /* offset in the major frame where a partition period starts */
    int64_t major_frame_ns;
    uint32_t start_condition; /* APEX START_CONDITION_TYPE */
    uint32_t initial_mode; /* COLD_START or WARM_START */
    uint32_t n_ports;
    uint32_t sandbox_flags; /* SKE_SANDBOX_*: what the partition's system-call filter allows */
    int32_t output_fd; /* its output file's descriptor (ima:Linux OutputFile), -1: none */
    uint32_t pad_output;
    ske_port_desc_t ports[SKE_MAX_PORTS];

    /* Hand-over. */
    _Atomic uint32_t grant_seq;
    _Atomic uint32_t yield_seq;
    _Atomic uint32_t ready; /* partition set it once attached and waiting for its first grant */
    _Atomic uint32_t ske_sleeping; /* the SKE sleeps on yield_seq: a yield must wake it */
    uint32_t pad_sleeping;
    _Atomic int64_t win_start_ns; /* current window, partition time */
    _Atomic int64_t win_end_ns;

    /* Partition → SKE, informational or requests. */
    _Atomic int64_t wake_mono_ns; /* CLOCK_MONOTONIC when the partition saw its grant */
    _Atomic int64_t yield_mono_ns; /* CLOCK_MONOTONIC when it yielded */
    _Atomic int64_t yield_t_ns; /* partition time when it yielded */
    _Atomic uint32_t mode; /* current operating mode as the partition reports it */
    _Atomic uint32_t mode_request; /* IDLE/COLD_START/WARM_START asked by SET_PARTITION_MODE */
    _Atomic uint32_t mode_request_seq;

    _Atomic uint32_t ev_head; /* written by the partition */
    _Atomic uint32_t ev_tail; /* written by the SKE */
    _Atomic uint32_t ev_dropped; /* events lost because the ring was full */

    /* Health monitoring. The System HM table (hm_level_t per system state and error) lets
     * the partition decide process-level errors at once; errors at partition or module level
     * are posted here for the SKE, which acts when the partition hands the CPU back. */
    uint8_t hm_level[SKE_HM_STATES][SKE_HM_ERRORS];
    _Atomic uint32_t hm_seq; /* partition: incremented when it posts an error */
    _Atomic uint32_t hm_ack; /* SKE: the hm_seq it has acted on */
    uint32_t hm_error; /* hm_error_t */
    uint32_t hm_state; /* hm_state_t */
    uint32_t hm_fatal; /* the reporting context cannot go on (a fault in initialisation) */
    int32_t hm_process; /* failed process id, 0 = the initialisation process */
    uint32_t hm_len;
    char hm_process_name[SKE_NAME_MAX];
    char hm_message[SKE_EVENT_TEXT];
    int64_t hm_t_ns;

    /* Module schedules (ARINC 653 Part 2). The SKE writes the list and the status; a
     * partition allowed to may ask for a switch, which takes effect at the next major frame. */
    uint32_t n_schedules;
    uint32_t schedule_change_allowed;
    int32_t schedule_ids[SKE_SCHEDULES];
    char schedule_names[SKE_SCHEDULES][SKE_NAME_MAX];
    _Atomic int32_t current_schedule; /* identifier */
    _Atomic int32_t next_schedule; /* identifier */
    _Atomic int64_t last_switch_ns;
    _Atomic int32_t schedule_request; /* identifier asked for (partition) */
    _Atomic uint32_t schedule_request_seq; /* partition: incremented per request */
    _Atomic uint32_t schedule_request_ack; /* SKE: the request it has taken */
    uint32_t pad1;

    /* Injected faults (ima-ske --fault), written by the SKE before exec. */
    uint32_t n_faults;
    uint32_t pad2;
    ske_fault_slot_t faults[SKE_FAULT_SLOTS];

    ske_event_t ev[SKE_EVENT_RING];
} ske_ctl_t;

/* ---- Port memory ---------------------------------------------------------------------- */

/* Sampling channel: one memory object per channel, the source maps it writable and every
 * destination read-only. Two slots: the writer fills the slot the readers do not see, then
 * publishes it by incrementing seq, so a reader never sees a half-written message even if
 * the writer was stopped in the middle of a write. */
typedef struct {
    uint32_t magic;
    uint32_t max_size;
    _Atomic uint32_t seq; /* number of messages written; 0 = empty; slot (seq & 1) is latest */
    uint32_t pad;
} ske_sampling_hdr_t;

typedef struct {
    int64_t t_ns; /* partition time of the write */
    uint32_t len;
    uint32_t seq;
    /* uint8_t data[slot payload] */
} ske_slot_hdr_t;

/* Queue: a single-producer single-consumer ring of `capacity` slots. A source queuing
 * port's queue is produced by the source partition and consumed by the SKE (transfer at
 * the end of the source's window); a destination port's queue is produced by the SKE and
 * consumed by the destination partition, whose tail lives in its port descriptor so that
 * the queue memory itself stays read-only for it. */
typedef struct {
    uint32_t magic;
    uint32_t max_size;
    uint32_t capacity;
    _Atomic uint32_t head; /* messages produced (wraps) */
    _Atomic uint32_t tail; /* source queues: messages consumed by the SKE */
    _Atomic uint32_t overflows; /* destination queues: messages lost to overflow (SKE) */
    uint32_t pad[2];
} ske_queue_hdr_t;

/* Sizes and slot addressing shared by both sides. */
size_t ske_slot_stride(uint32_t max_size);
size_t ske_sampling_map_size(uint32_t max_size);
size_t ske_queue_map_size(uint32_t max_size, uint32_t capacity);

void ske_sampling_init(void *mem, uint32_t max_size);
/* Writes a message (len ≤ max_size checked by the caller). */
void ske_sampling_write(void *mem, uint32_t max_size, const void *msg, uint32_t len, int64_t t_ns);
/* Copies the latest message; returns false when none was ever written. *len is clamped to
 * max_size so that a corrupted header cannot make the reader overrun its buffer. */
bool ske_sampling_read(const void *mem, uint32_t max_size, void *msg, uint32_t *len,
                       int64_t *t_ns);
/* The same, also giving the message's sequence number (1, 2, ... per write): a reader tells a
 * message it has read already from a new one by it. */
bool ske_sampling_read_seq(const void *mem, uint32_t max_size, void *msg, uint32_t *len,
                           int64_t *t_ns, uint32_t *seq);
/* The sequence number and time stamp of the latest message, without copying it; false when
 * none was ever written. */
bool ske_sampling_latest(const void *mem, uint32_t max_size, uint32_t *seq, int64_t *t_ns);
/* The latest message in place, its length (clamped to max_size) and sequence number; NULL
 * when none was ever written. For the SKE, between windows, when no writer runs. */
void *ske_sampling_latest_msg(void *mem, uint32_t max_size, uint32_t *len, uint32_t *seq);

void ske_queue_init(void *mem, uint32_t max_size, uint32_t capacity);
/* Number of messages between tail and head, or UINT32_MAX if the indices are inconsistent. */
uint32_t ske_queue_count(const void *mem, uint32_t capacity, uint32_t tail);
/* Producer side. Returns false when full. */
bool ske_queue_push(void *mem, uint32_t max_size, uint32_t capacity, uint32_t tail,
                    const void *msg, uint32_t len, int64_t t_ns);
/* The time stamped on the message at `tail` (a destination queue: its arrival). */
int64_t ske_queue_head_time(const void *mem, uint32_t max_size, uint32_t capacity, uint32_t tail);
/* Consumer side: copy the message at `tail` (the caller then advances its tail). */
void ske_queue_peek(const void *mem, uint32_t max_size, uint32_t capacity, uint32_t tail,
                    void *msg, uint32_t *len, int64_t *t_ns);

/* ---- Hand-over helpers ---------------------------------------------------------------- */

int64_t ske_mono_ns(void);
/* Shared (not process-private) futex on a word of the control block. rel may be NULL. */
int ske_futex_wait(_Atomic uint32_t *word, uint32_t expected, const struct timespec *rel);
int ske_futex_wake(_Atomic uint32_t *word);

#endif /* SKE_ABI_H */
