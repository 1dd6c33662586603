/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of hm_decide over the whole table: every system state × error × configured level
 * × origin × error handler or none × failed context able to go on or not × every configured
 * module and partition action; then cases written out by hand from the standard and the
 * example module. */
#include <stdio.h>
#include <string.h>

#include "hm/hm.h"
#include "hm_test.h"

static const hm_level_t levels[] = {HM_LEVEL_MODULE, HM_LEVEL_PARTITION, HM_LEVEL_PROCESS};
static const hm_action_t module_actions[] = {HM_ACT_IGNORE, HM_ACT_SHUTDOWN, HM_ACT_RESET};
static const hm_action_t partition_actions[] = {HM_ACT_IGNORE, HM_ACT_IDLE, HM_ACT_WARM_START,
                                                HM_ACT_COLD_START};
#define N_OF(a) (sizeof(a) / sizeof((a)[0]))

/* What the standard asks, spelt out case by case. */
static hm_decision_t expected(hm_level_t configured, hm_action_t module, hm_action_t partition,
                              hm_origin_t origin, bool handler, bool fatal)
{
    hm_decision_t d = {.level = configured, .partition_action = HM_ACT_IGNORE};
    bool handler_takes_it = handler && origin == HM_ORIGIN_PROCESS;
    switch (configured) {
    case HM_LEVEL_PROCESS:
        if (handler_takes_it) {
            d.action = HM_ACT_ERROR_HANDLER;
            break;
        }
        d.level = HM_LEVEL_PARTITION;
        d.flags = HM_DECIDE_ESCALATED; /* the partition level decides */
        /* fall through */
    case HM_LEVEL_PARTITION:
        d.action = partition == HM_ACT_IGNORE && fatal ? HM_ACT_IDLE : partition;
        d.partition_action = d.action;
        if (partition == HM_ACT_IGNORE && fatal)
            d.flags |= HM_DECIDE_CANNOT_GO_ON;
        break;
    case HM_LEVEL_MODULE:
        d.action = module;
        if (module == HM_ACT_IGNORE && fatal) {
            d.partition_action = HM_ACT_IDLE;
            d.flags = HM_DECIDE_CANNOT_GO_ON;
        }
        break;
    }
    return d;
}

static int mismatches_shown;

static void check_case(hm_state_t s, hm_error_t e, hm_level_t level, hm_action_t module,
                       hm_action_t partition, hm_origin_t origin, bool handler, bool fatal)
{
    hm_system_table_t sys;
    hm_partition_table_t part;
    hm_system_defaults(&sys);
    hm_partition_defaults(&part);
    sys.level[s][e] = (uint8_t)level;
    sys.module_action[s][e] = (uint8_t)module;
    part.action[s][e] = (uint8_t)partition;
    hm_decision_t got = hm_decide(&sys, &part, s, e, origin, handler, fatal);
    hm_decision_t want = expected(level, module, partition, origin, handler, fatal);
    bool ok = got.level == want.level && got.action == want.action &&
              got.partition_action == want.partition_action && got.flags == want.flags &&
              (got.note != NULL) == (want.flags != 0);
    if (!ok) {
        hm_test_failures++;
        if (mismatches_shown++ < 20)
            fprintf(stderr,
                    "state %s error %s level %s module %s partition %s origin %d handler %d "
                    "fatal %d: got %s/%s/%s flags %u, want %s/%s/%s flags %u\n",
                    hm_state_name(s), hm_error_name(e), hm_level_name(level),
                    hm_action_name(module), hm_action_name(partition), (int)origin, handler,
                    fatal, hm_level_name(got.level), hm_action_name(got.action),
                    hm_action_name(got.partition_action), got.flags, hm_level_name(want.level),
                    hm_action_name(want.action), hm_action_name(want.partition_action),
                    want.flags);
    }
    /* The decision is the cell's: the SKE and the partition, deciding the same error, agree. */
    hm_decision_t again = hm_decide(&sys, &part, s, e, origin, handler, fatal);
    CHECK(memcmp(&again, &got, sizeof got) == 0);
}

static void test_whole_table(void)
{
    int cases = 0;
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 1; e < HM_ERR_COUNT; e++)
            for (size_t l = 0; l < N_OF(levels); l++)
                for (size_t m = 0; m < N_OF(module_actions); m++)
                    for (size_t p = 0; p < N_OF(partition_actions); p++)
                        for (int o = 0; o < HM_ORIGIN_COUNT; o++)
                            for (int h = 0; h < 2; h++)
                                for (int f = 0; f < 2; f++) {
                                    check_case((hm_state_t)s, (hm_error_t)e, levels[l],
                                               module_actions[m], partition_actions[p],
                                               (hm_origin_t)o, h, f);
                                    cases++;
                                }
    CHECK(cases == 4 * 10 * 3 * 3 * 4 * 4 * 2 * 2);
}

/* One cell set never changes another cell's decision. */
static void test_cells_independent(void)
{
    hm_system_table_t sys;
    hm_partition_table_t part;
    hm_system_defaults(&sys);
    hm_partition_defaults(&part);
    sys.level[HM_STATE_PROCESS][HM_ERR_MEMORY_VIOLATION] = HM_LEVEL_MODULE;
    sys.module_action[HM_STATE_PROCESS][HM_ERR_MEMORY_VIOLATION] = HM_ACT_SHUTDOWN;
    part.action[HM_STATE_PROCESS][HM_ERR_NUMERIC_ERROR] = HM_ACT_COLD_START;
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 1; e < HM_ERR_COUNT; e++) {
            hm_decision_t d = hm_decide(&sys, &part, (hm_state_t)s, (hm_error_t)e,
                                        HM_ORIGIN_PROCESS, true, false);
            if (s == HM_STATE_PROCESS && e == HM_ERR_MEMORY_VIOLATION) {
                CHECK(d.level == HM_LEVEL_MODULE && d.action == HM_ACT_SHUTDOWN);
                continue;
            }
            CHECK(d.level == HM_LEVEL_PARTITION && d.flags == 0);
            if (s == HM_STATE_PROCESS && e == HM_ERR_NUMERIC_ERROR)
                CHECK(d.action == HM_ACT_COLD_START);
            else if (e == HM_ERR_DEADLINE_MISSED || e == HM_ERR_WINDOW_OVERRUN)
                CHECK(d.action == HM_ACT_IGNORE);
            else
                CHECK(d.action == HM_ACT_IDLE);
        }
}

/* Cases of docs/health-monitoring.md, each written out. */
static void test_by_hand(void)
{
    hm_system_table_t sys;
    hm_partition_table_t part;
    hm_system_defaults(&sys);
    hm_partition_defaults(&part);
    const hm_state_t P = HM_STATE_PROCESS;
    sys.level[P][HM_ERR_MEMORY_VIOLATION] = HM_LEVEL_PROCESS;
    part.action[P][HM_ERR_MEMORY_VIOLATION] = HM_ACT_COLD_START;

    /* r_segv: PROCESS level, the partition has an error handler. */
    hm_decision_t d =
        hm_decide(&sys, &part, P, HM_ERR_MEMORY_VIOLATION, HM_ORIGIN_PROCESS, true, false);
    CHECK(d.level == HM_LEVEL_PROCESS && d.action == HM_ACT_ERROR_HANDLER);
    CHECK(d.partition_action == HM_ACT_IGNORE && d.flags == 0 && d.note == NULL);

    /* r_port: the same error without an error handler: COLD_START at partition level. */
    d = hm_decide(&sys, &part, P, HM_ERR_MEMORY_VIOLATION, HM_ORIGIN_PROCESS, false, false);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_COLD_START);
    CHECK(d.partition_action == HM_ACT_COLD_START && d.flags == HM_DECIDE_ESCALATED);
    CHECK(d.note && strcmp(d.note, "no process-level handling possible: escalated to the "
                                   "partition level") == 0);

    /* The error handler's own fault never goes back to it. */
    d = hm_decide(&sys, &part, P, HM_ERR_MEMORY_VIOLATION, HM_ORIGIN_ERROR_HANDLER, true, false);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_COLD_START);

    /* A fault in initialisation that the table IGNOREs: idled. */
    part.action[HM_STATE_PARTITION_INIT][HM_ERR_NUMERIC_ERROR] = HM_ACT_IGNORE;
    d = hm_decide(&sys, &part, HM_STATE_PARTITION_INIT, HM_ERR_NUMERIC_ERROR,
                  HM_ORIGIN_PARTITION, false, true);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_IDLE);
    CHECK(d.partition_action == HM_ACT_IDLE && d.flags == HM_DECIDE_CANNOT_GO_ON);
    CHECK(d.note && strcmp(d.note, "IGNORE requested, but the failed initialisation cannot go "
                                   "on: the partition is idled") == 0);

    /* The same at module level: the module IGNOREs, the partition is idled. */
    sys.level[HM_STATE_PARTITION_INIT][HM_ERR_NUMERIC_ERROR] = HM_LEVEL_MODULE;
    d = hm_decide(&sys, &part, HM_STATE_PARTITION_INIT, HM_ERR_NUMERIC_ERROR,
                  HM_ORIGIN_PARTITION, false, true);
    CHECK(d.level == HM_LEVEL_MODULE && d.action == HM_ACT_IGNORE);
    CHECK(d.partition_action == HM_ACT_IDLE && d.flags == HM_DECIDE_CANNOT_GO_ON);
    CHECK(d.note && strcmp(d.note, "module IGNORE, but the failed initialisation cannot go on: "
                                   "the partition is idled") == 0);

    /* A module SHUTDOWN leaves the partition to the module's end. */
    sys.module_action[HM_STATE_PARTITION_INIT][HM_ERR_NUMERIC_ERROR] = HM_ACT_SHUTDOWN;
    d = hm_decide(&sys, &part, HM_STATE_PARTITION_INIT, HM_ERR_NUMERIC_ERROR,
                  HM_ORIGIN_PARTITION, false, true);
    CHECK(d.action == HM_ACT_SHUTDOWN && d.partition_action == HM_ACT_IGNORE && d.flags == 0);

    /* Defaults: a partition exit is IDLEd, a window overrun IGNOREd, by the SKE. */
    d = hm_decide(&sys, &part, P, HM_ERR_PARTITION_EXIT, HM_ORIGIN_SKE, false, false);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_IDLE && d.flags == 0);
    d = hm_decide(&sys, &part, P, HM_ERR_WINDOW_OVERRUN, HM_ORIGIN_SKE, true, false);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_IGNORE && d.flags == 0);

    /* Without a Partition HM table (the APEX library's call), the defaults stand in. */
    d = hm_decide(&sys, NULL, P, HM_ERR_MEMORY_VIOLATION, HM_ORIGIN_PROCESS, false, false);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_IDLE);
    d = hm_decide(&sys, NULL, P, HM_ERR_MEMORY_VIOLATION, HM_ORIGIN_PROCESS, true, false);
    CHECK(d.level == HM_LEVEL_PROCESS && d.action == HM_ACT_ERROR_HANDLER);
}

/* Garbage in a table (the APEX library's copy lives in memory the partition can write) never
 * yields a level or an action of the wrong kind. */
static void test_garbage(void)
{
    hm_system_table_t sys;
    hm_partition_table_t part;
    memset(&sys, 0xEE, sizeof sys);
    memset(&part, 0xEE, sizeof part);
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 1; e < HM_ERR_COUNT; e++) {
            hm_decision_t d = hm_decide(&sys, &part, (hm_state_t)s, (hm_error_t)e,
                                        HM_ORIGIN_PROCESS, true, false);
            CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_IDLE);
        }
    hm_system_defaults(&sys);
    hm_decision_t d = hm_decide(&sys, &part, (hm_state_t)7, HM_ERR_COUNT, HM_ORIGIN_PROCESS,
                                true, false);
    CHECK(d.level == HM_LEVEL_PARTITION && d.action == HM_ACT_IDLE);
}

void hm_test_decide(void)
{
    test_whole_table();
    test_cells_independent();
    test_by_hand();
    test_garbage();
}
