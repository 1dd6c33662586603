/* SPDX-License-Identifier: Apache-2.0 */
/* ARINC 653 Part 1 health monitoring: the errors the emulator detects, the system states it
 * distinguishes, and the three tables (System, Module, Partition) that decide at which level
 * an error is handled and with which action. */
#ifndef HM_HM_H
#define HM_HM_H

#include <stdbool.h>
#include <stdint.h>

/* Error identifiers (the ErrorIdentifier of the HM tables; implementation-defined in the
 * standard). 1-8 are the APEX error codes as detected in a partition; 9 and 10 are what the
 * SKE alone sees. 0 is unused so that a zeroed table entry is recognisably "not set". */
typedef enum {
    HM_ERR_DEADLINE_MISSED = 1, /* a process missed its deadline */
    HM_ERR_APPLICATION_ERROR = 2, /* RAISE_APPLICATION_ERROR */
    HM_ERR_NUMERIC_ERROR = 3, /* SIGFPE */
    HM_ERR_ILLEGAL_REQUEST = 4, /* a system call the sandbox denies (SIGSYS) */
    HM_ERR_STACK_OVERFLOW = 5, /* a write into a stack's guard page */
    HM_ERR_MEMORY_VIOLATION = 6, /* SIGSEGV, SIGBUS outside a stack guard */
    HM_ERR_HARDWARE_FAULT = 7, /* SIGILL */
    HM_ERR_POWER_FAIL = 8, /* never detected in emulation; configurable for completeness */
    HM_ERR_WINDOW_OVERRUN = 9, /* the partition kept the CPU past its window (DEADLINE_MISSED) */
    HM_ERR_PARTITION_EXIT = 10, /* the partition's process ended without being asked to */
    HM_ERR_COUNT = 11,
} hm_error_t;

/* System states of the System HM table (SystemState). */
typedef enum {
    HM_STATE_MODULE_INIT = 0, /* the SKE is starting the module */
    HM_STATE_PARTITION_INIT = 1, /* the partition's initialisation (COLD_START, WARM_START) */
    HM_STATE_PROCESS = 2, /* an ARINC process runs (NORMAL mode) */
    HM_STATE_ERROR_HANDLER = 3, /* the partition's error handler runs */
    HM_STATE_COUNT = 4,
} hm_state_t;

typedef enum { HM_LEVEL_MODULE = 0, HM_LEVEL_PARTITION = 1, HM_LEVEL_PROCESS = 2 } hm_level_t;

typedef enum {
    HM_ACT_IGNORE = 0,
    HM_ACT_IDLE = 1, /* partition */
    HM_ACT_WARM_START = 2, /* partition */
    HM_ACT_COLD_START = 3, /* partition */
    HM_ACT_SHUTDOWN = 4, /* module */
    HM_ACT_RESET = 5, /* module */
    HM_ACT_ERROR_HANDLER = 6, /* process level: the partition's error handler runs */
} hm_action_t;

/* The System HM table (level of each error in each state) and the Module HM table. */
typedef struct {
    uint8_t level[HM_STATE_COUNT][HM_ERR_COUNT];
    uint8_t module_action[HM_STATE_COUNT][HM_ERR_COUNT];
} hm_system_table_t;

/* A Partition HM table. */
typedef struct {
    uint8_t action[HM_STATE_COUNT][HM_ERR_COUNT];
} hm_partition_table_t;

/* The tables a module without HM tables gets: every error at partition level; partition
 * action IDLE (fail-stop) for faults, IGNORE for timing errors (a window overrun: the
 * partition is already stopped for the rest of its window; a missed deadline: recorded, a
 * host under load must not idle a healthy partition); module action IGNORE. */
void hm_system_defaults(hm_system_table_t *t);
void hm_partition_defaults(hm_partition_table_t *t);

hm_level_t hm_level_of(const hm_system_table_t *t, hm_state_t state, hm_error_t err);
hm_action_t hm_module_action(const hm_system_table_t *t, hm_state_t state, hm_error_t err);
hm_action_t hm_partition_action(const hm_partition_table_t *t, hm_state_t state, hm_error_t err);

/* Names as the standard spells them (trace and configuration). NULL when out of range. */
const char *hm_error_name(hm_error_t err);
const char *hm_state_name(hm_state_t s);
const char *hm_level_name(hm_level_t l);
const char *hm_action_name(hm_action_t a);
/* Parse a name; false if unknown. */
bool hm_level_parse(const char *s, hm_level_t *out);
bool hm_action_parse(const char *s, hm_action_t *out);
bool hm_error_parse(const char *s, hm_error_t *out);

/* The APEX ERROR_CODE_TYPE value reported to an error handler for an error identifier. */
int hm_apex_error_code(hm_error_t err);

/* ---- decisions ------------------------------------------------------------------------- */

/* Where an error was raised. Only an error of one of the partition's ARINC processes can be
 * taken by its error handler (ARINC 653 Part 1, 2.4.2.3). */
typedef enum {
    HM_ORIGIN_PROCESS = 0, /* an ARINC process of the partition */
    HM_ORIGIN_ERROR_HANDLER = 1, /* the error handler process itself */
    HM_ORIGIN_PARTITION = 2, /* the partition outside any process: initialisation, scheduler */
    HM_ORIGIN_SKE = 3, /* the SKE, about the partition: a window overrun, an exit */
    HM_ORIGIN_COUNT = 4,
} hm_origin_t;

/* Why a decision is not the plain reading of the tables (hm_decision_t.flags). */
enum {
    /* PROCESS level, but no error handler can take the error: the partition level decides
     * (ARINC 653 Part 1, 2.4.2.3). */
    HM_DECIDE_ESCALATED = 1u << 0,
    /* IGNORE configured, but the failed context cannot go on (a fault outside any process,
     * where no process can be stopped in its place): the partition is idled, since ignoring
     * would leave it hung. */
    HM_DECIDE_CANNOT_GO_ON = 1u << 1,
};

typedef struct {
    hm_level_t level; /* the level that handles the error */
    /* That level's action: ERROR_HANDLER at PROCESS level; IGNORE, IDLE, WARM_START or
     * COLD_START at PARTITION level; IGNORE, SHUTDOWN or RESET at MODULE level. */
    hm_action_t action;
    /* What becomes of the failed partition itself: IGNORE (it goes on), IDLE, WARM_START or
     * COLD_START. IGNORE under a module SHUTDOWN or RESET, which act on the whole module. */
    hm_action_t partition_action;
    unsigned flags; /* HM_DECIDE_* */
    const char *note; /* one sentence on the flags for the trace; NULL when flags is 0 */
} hm_decision_t;

/* The health monitor's decision on one error: its level in the System HM table for `state`,
 * escalated to the partition level when no error handler can take it, then the Module or
 * Partition HM table's action, IGNORE overridden when the failed context cannot go on.
 * `part` may be NULL (a caller that only tells PROCESS level from the others: the partition's
 * own APEX library); the default Partition HM table stands in for it. `has_error_handler`:
 * the partition created one. `fatal_context`: the failed context cannot go on and no process
 * can be stopped in its place. Pure: no state, no I/O, async-signal-safe. */
hm_decision_t hm_decide(const hm_system_table_t *sys, const hm_partition_table_t *part,
                        hm_state_t state, hm_error_t err, hm_origin_t origin,
                        bool has_error_handler, bool fatal_context);

#endif /* HM_HM_H */
