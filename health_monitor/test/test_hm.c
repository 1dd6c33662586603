/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the health monitor: the tables (defaults, look-ups over every state and
 * error, out-of-range entries, names) here, the decisions in test_hm_decide.c. */
#include <stdio.h>
#include <string.h>

#include "hm/hm.h"
#include "hm_test.h"

int hm_test_failures;

static void test_defaults(void)
{
    hm_system_table_t sys;
    hm_partition_table_t part;
    hm_system_defaults(&sys);
    hm_partition_defaults(&part);
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 1; e < HM_ERR_COUNT; e++) {
            CHECK(hm_level_of(&sys, (hm_state_t)s, (hm_error_t)e) == HM_LEVEL_PARTITION);
            CHECK(hm_module_action(&sys, (hm_state_t)s, (hm_error_t)e) == HM_ACT_IGNORE);
            hm_action_t want = e == HM_ERR_WINDOW_OVERRUN || e == HM_ERR_DEADLINE_MISSED
                                   ? HM_ACT_IGNORE
                                   : HM_ACT_IDLE;
            CHECK(hm_partition_action(&part, (hm_state_t)s, (hm_error_t)e) == want);
        }
}

/* Every cell of the tables is its own: setting one changes that one look-up only. */
static void test_lookup_is_per_cell(void)
{
    static const hm_level_t levels[] = {HM_LEVEL_MODULE, HM_LEVEL_PARTITION, HM_LEVEL_PROCESS};
    static const hm_action_t part_actions[] = {HM_ACT_IGNORE, HM_ACT_IDLE, HM_ACT_WARM_START,
                                               HM_ACT_COLD_START};
    static const hm_action_t mod_actions[] = {HM_ACT_IGNORE, HM_ACT_SHUTDOWN, HM_ACT_RESET};
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 1; e < HM_ERR_COUNT; e++)
            for (int k = 0; k < 3; k++) {
                hm_system_table_t sys;
                hm_partition_table_t part;
                hm_system_defaults(&sys);
                hm_partition_defaults(&part);
                sys.level[s][e] = (uint8_t)levels[k];
                sys.module_action[s][e] = (uint8_t)mod_actions[k];
                part.action[s][e] = (uint8_t)part_actions[k + 1];
                for (int s2 = 0; s2 < HM_STATE_COUNT; s2++)
                    for (int e2 = 1; e2 < HM_ERR_COUNT; e2++) {
                        bool here = s2 == s && e2 == e;
                        hm_level_t l = hm_level_of(&sys, (hm_state_t)s2, (hm_error_t)e2);
                        CHECK(l == (here ? levels[k] : HM_LEVEL_PARTITION));
                        hm_action_t m = hm_module_action(&sys, (hm_state_t)s2, (hm_error_t)e2);
                        CHECK(m == (here ? mod_actions[k] : HM_ACT_IGNORE));
                        hm_action_t a = hm_partition_action(&part, (hm_state_t)s2, (hm_error_t)e2);
                        hm_action_t dflt = e2 == HM_ERR_WINDOW_OVERRUN || e2 == HM_ERR_DEADLINE_MISSED
                                               ? HM_ACT_IGNORE
                                               : HM_ACT_IDLE;
                        CHECK(a == (here ? part_actions[k + 1] : dflt));
                    }
            }
}

/* Garbage in a table (it is shared with partitions in the control block) never yields an
 * action of the wrong kind. */
static void test_out_of_range_entries(void)
{
    hm_system_table_t sys;
    hm_partition_table_t part;
    hm_system_defaults(&sys);
    hm_partition_defaults(&part);
    sys.level[2][3] = 77;
    sys.module_action[2][3] = HM_ACT_COLD_START; /* a partition action in the module table */
    part.action[2][3] = HM_ACT_SHUTDOWN; /* a module action in a partition table */
    CHECK(hm_level_of(&sys, HM_STATE_PROCESS, HM_ERR_NUMERIC_ERROR) == HM_LEVEL_PARTITION);
    CHECK(hm_module_action(&sys, HM_STATE_PROCESS, HM_ERR_NUMERIC_ERROR) == HM_ACT_IGNORE);
    CHECK(hm_partition_action(&part, HM_STATE_PROCESS, HM_ERR_NUMERIC_ERROR) == HM_ACT_IDLE);
    CHECK(hm_level_of(&sys, (hm_state_t)9, HM_ERR_NUMERIC_ERROR) == HM_LEVEL_PARTITION);
    CHECK(hm_level_of(&sys, HM_STATE_PROCESS, (hm_error_t)0) == HM_LEVEL_PARTITION);
    CHECK(hm_level_of(&sys, HM_STATE_PROCESS, HM_ERR_COUNT) == HM_LEVEL_PARTITION);
}

static void test_names(void)
{
    for (int e = 1; e < HM_ERR_COUNT; e++) {
        hm_error_t back;
        CHECK(hm_error_name((hm_error_t)e) != NULL);
        CHECK(hm_error_parse(hm_error_name((hm_error_t)e), &back) && back == (hm_error_t)e);
    }
    CHECK(hm_error_name((hm_error_t)0) == NULL && hm_error_name(HM_ERR_COUNT) == NULL);
    hm_level_t l;
    CHECK(hm_level_parse("PROCESS", &l) && l == HM_LEVEL_PROCESS);
    CHECK(!hm_level_parse("process", &l));
    hm_action_t a;
    CHECK(hm_action_parse("COLD_START", &a) && a == HM_ACT_COLD_START);
    CHECK(!hm_action_parse("ERROR_HANDLER", &a)); /* not configurable: the level decides it */
    CHECK(strcmp(hm_state_name(HM_STATE_ERROR_HANDLER), "ERROR_HANDLER") == 0);
    /* The APEX ERROR_CODE_TYPE values an error handler reads. */
    CHECK(hm_apex_error_code(HM_ERR_DEADLINE_MISSED) == 0);
    CHECK(hm_apex_error_code(HM_ERR_MEMORY_VIOLATION) == 5);
    CHECK(hm_apex_error_code(HM_ERR_POWER_FAIL) == 7);
    CHECK(hm_apex_error_code(HM_ERR_WINDOW_OVERRUN) == 0); /* a deadline missed */
    CHECK(hm_apex_error_code(HM_ERR_PARTITION_EXIT) == 6); /* HARDWARE_FAULT: no code of its own */
}

int main(void)
{
    test_defaults();
    test_lookup_is_per_cell();
    test_out_of_range_entries();
    test_names();
    hm_test_decide();
    if (hm_test_failures)
        fprintf(stderr, "%d check(s) failed\n", hm_test_failures);
    else
        printf("test_hm: all checks passed\n");
    return hm_test_failures ? 1 : 0;
}
