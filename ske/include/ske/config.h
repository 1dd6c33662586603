/* SPDX-License-Identifier: Apache-2.0 */
/* The ARINC 653 module configuration as the SKE reads it: partitions, ports, schedule,
 * channels, loaded from the module XML and checked against the rules of ARINC 653 Part 1. */
#ifndef SKE_CONFIG_H
#define SKE_CONFIG_H

#include <stdbool.h>
#include <stdint.h>

#include "hm/hm.h"
#include "ske_abi.h"

#define SKE_MAX_PARTITIONS 32
#define SKE_MAX_WINDOWS 256
#define SKE_MAX_SCHEDULES 8
#define SKE_MAX_CHANNELS 256
#define SKE_MAX_DESTINATIONS 16
#define SKE_MAX_ARGS 32
#define SKE_PATH_MAX 4096
#define SKE_PORT_BYTES_MAX (64u << 20) /* messages a queuing port may hold, in bytes */

/* Status codes of the SKE library (0 = ok). */
enum {
    SKE_OK = 0,
    SKE_E_CONFIG = -1, /* invalid module: see the diagnostic */
    SKE_E_IO = -2,
    SKE_E_NOMEM = -3,
    SKE_E_SYS = -4, /* a system call failed: see errno */
    SKE_E_PARTITION = -5, /* a partition could not be started */
};

/* One diagnostic line: "FILE:LINE: error: ELEMENT: message (rule: ...)". */
typedef struct {
    char file[SKE_PATH_MAX];
    int line;
    char element[64];
    char message[768];
    char rule[160];
} ske_diag_t;

typedef struct {
    char name[SKE_NAME_MAX];
    ske_port_kind_t kind;
    ske_port_dir_t dir;
    uint32_t max_size;
    uint32_t max_nb; /* queuing */
    int64_t refresh_ns; /* sampling */
    int channel; /* index into module channels, -1 if unconnected */
    int line;
} ske_port_cfg_t;

typedef struct {
    char name[SKE_NAME_MAX];
    uint32_t stack_size; /* informational: from the Process element */
    int line;
} ske_process_cfg_t;

typedef struct {
    int32_t id;
    char name[SKE_NAME_MAX];
    char criticality[16];
    bool system_partition;
    char entry_point[64];
    /* Linux extension */
    char executable[SKE_PATH_MAX]; /* resolved absolute path after load */
    char exe_name[SKE_PATH_MAX]; /* as written in the module */
    int argc;
    char *argv[SKE_MAX_ARGS]; /* argv[0] is the partition name */
    /* Its output file (ima:Linux OutputFile): opened by the SKE, handed to the partition as
     * the one file it may write; "" for none. As written; resolved against the SKE's output
     * folder (--output-dir, default the module file's folder) when the SKE opens it. */
    char output_file[SKE_PATH_MAX];
    /* ima:Linux HealthMonitorLogPort: the destination queuing port that receives the
     * module's health-monitor decisions (ske_hm_log_t); index in ports, -1 for none. */
    int hm_log_port;
    char hm_log_port_name[SKE_NAME_MAX];
    /* schedule: period_ns is the same in every module schedule; duration and anchor are the
     * initial schedule's, with each schedule's own in the _in arrays */
    int64_t period_ns;
    int64_t duration_ns; /* window time per period */
    int64_t period_anchor_ns;
    int n_windows; /* in all schedules */
    int64_t duration_in[SKE_MAX_SCHEDULES];
    int64_t anchor_in[SKE_MAX_SCHEDULES];
    int windows_in[SKE_MAX_SCHEDULES];
    bool schedule_change; /* may call SET_MODULE_SCHEDULE (ima:ScheduleChange) */
    /* memory */
    uint64_t memory_bytes; /* sum of Memory_Requirements, 0 if none declared */
    int n_ports;
    ske_port_cfg_t ports[SKE_MAX_PORTS];
    int n_processes;
    ske_process_cfg_t processes[SKE_MAX_PORTS];
    hm_partition_table_t hm; /* its Partition HM table (defaults where none is given) */
    int line;
} ske_partition_cfg_t;

typedef struct {
    int32_t id;
    int schedule; /* index into module schedules */
    int partition; /* index into module partitions */
    int64_t offset_ns;
    int64_t duration_ns;
    bool period_start;
    int line;
} ske_window_cfg_t;

typedef struct {
    int partition;
    int port;
} ske_endpoint_t;

typedef struct {
    int32_t id;
    char name[SKE_NAME_MAX];
    ske_port_kind_t kind;
    ske_endpoint_t src;
    int n_dst;
    ske_endpoint_t dst[SKE_MAX_DESTINATIONS];
    int line;
} ske_channel_cfg_t;

/* A module schedule (ARINC 653 Part 2 allows several; the initial one runs first). */
typedef struct {
    int32_t id;
    char name[SKE_NAME_MAX];
    int first_window; /* its windows: m->windows[first_window .. first_window + n_windows) */
    int n_windows;
    bool initial;
    int line;
} ske_schedule_cfg_t;

typedef struct {
    char path[SKE_PATH_MAX];
    char module_name[64];
    char node[SKE_NAME_MAX];
    ske_time_mode_t time_mode;
    int64_t major_frame_ns; /* the same in every module schedule */
    int n_schedules; /* 0 only for a module built by hand: then the windows are one schedule */
    ske_schedule_cfg_t schedules[SKE_MAX_SCHEDULES];
    int initial_schedule;
    int n_partitions;
    ske_partition_cfg_t partitions[SKE_MAX_PARTITIONS];
    int n_windows; /* grouped by schedule, sorted by offset within each */
    ske_window_cfg_t windows[SKE_MAX_WINDOWS];
    int n_channels;
    ske_channel_cfg_t channels[SKE_MAX_CHANNELS];
    hm_system_table_t hm; /* System and Module HM tables (defaults where none is given) */
} ske_module_cfg_t;

typedef struct {
    const char *schema_dir; /* folder with ima653_module.xsd; NULL = built-in default */
    const char *partition_path; /* colon-separated folders searched for bare executables */
    bool resolve_executables; /* false: do not require the executables to exist */
} ske_load_opts_t;

/* Loads and checks a module. On SKE_E_CONFIG the diagnostic says what is wrong.
 * The returned module is freed with ske_config_free(). */
int ske_config_load(const char *path, const ske_load_opts_t *opts, ske_module_cfg_t **out,
                    ske_diag_t *diag);
void ske_config_free(ske_module_cfg_t *m);

/* "FILE:LINE: error: ELEMENT: message (rule: ...)" into buf. */
void ske_diag_format(const ske_diag_t *d, char *buf, size_t len);

/* Decimal seconds ("0.05", "1", "0.000125") to nanoseconds, exactly: no binary floating
 * point. Returns false on anything else (sign, exponent, more than 9 decimals, overflow). */
bool ske_parse_seconds(const char *s, int64_t *ns);
/* Non-negative integer, decimal or 0x-hexadecimal, with no trailing characters. */
bool ske_parse_u64(const char *s, uint64_t *v);

/* Index of a partition by identifier or -1. */
int ske_config_partition_by_id(const ske_module_cfg_t *m, int32_t id);
int ske_config_port_by_name(const ske_partition_cfg_t *p, const char *name);

#endif /* SKE_CONFIG_H */
