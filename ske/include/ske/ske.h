/* SPDX-License-Identifier: Apache-2.0 */
/* The Separation Kernel Emulator: one ARINC 653 processor that runs a module's partitions as
 * Linux processes under its cyclic plan. */
#ifndef SKE_SKE_H
#define SKE_SKE_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "ske/config.h"

typedef struct ske ske_t;

typedef struct {
    int64_t frames; /* major frames to run; < 0 runs until stopped */
    int time_mode; /* -1: as the module says; else ske_time_mode_t */
    const char *trace_path; /* JSON lines, "-" for stdout, NULL for none */
    const char *stats_path; /* JSON summary written at the end, NULL for none */
    const char *node; /* node name in the trace; NULL: the module's */
    const char *lockstep_path; /* CAN bus socket whose time quanta gate the windows, or NULL */
    uint32_t node_index; /* node (redundancy channel) number given to the bus, 0 for none */
    bool quiet;
    /* Faults to inject, each CLASS:fid=ID,at=TIME,... (faultinject/include/fi/spec.h). */
    const char *const *faults;
    int n_faults;
    /* Test switches, NAME[=VALUE]: deliberate breaches of isolation, for testing oracles. */
    const char *const *test_switches;
    int n_test_switches;
    bool trace_port_hashes; /* a port_hash event per source port written in a window */
    /* Folder of relative output files (ima:Linux OutputFile); NULL: the module file's. */
    const char *output_dir;
} ske_run_opts_t;

/* Checks the faults and test switches of opts against the module: SKE_OK, or SKE_E_CONFIG
 * with one line in err. ske_create checks them too. */
int ske_check_options(const ske_module_cfg_t *cfg, const ske_run_opts_t *opts, char *err,
                      size_t errlen);

/* Prepares port memory and control blocks; starts no process. err gets one line;
 * SKE_E_CONFIG: a fault or test switch that cannot apply to the module. */
int ske_create(const ske_module_cfg_t *cfg, const ske_run_opts_t *opts, ske_t **out, char *err,
               size_t errlen);
/* Starts the partitions and runs the cyclic plan until the frame count is reached or a stop
 * is requested; then stops every partition. Returns SKE_OK or a negative status (err says
 * why). */
int ske_run(ske_t *ske, char *err, size_t errlen);
/* Both are async-signal-safe: call them from SIGINT/SIGTERM and SIGCHLD handlers. */
void ske_request_stop(ske_t *ske, int signo);
void ske_notify_child(ske_t *ske);
/* The signal that stopped the run, or 0. */
int ske_stop_signal(const ske_t *ske);
/* Whether a module-level SHUTDOWN of the health monitor ended the run. */
bool ske_shut_down_by_hm(const ske_t *ske);
/* Kills any partition still alive and frees everything. */
void ske_destroy(ske_t *ske);

#endif /* SKE_SKE_H */
