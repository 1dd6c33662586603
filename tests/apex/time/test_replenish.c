/* SPDX-License-Identifier: Apache-2.0 */
/* REPLENISH (ARINC 653 Part 1, 3.4.2): the caller's deadline becomes now + BUDGET_TIME (none
 * for an infinite budget); a periodic process cannot push it past its next release point.
 * The partition period is 20 ms; its window is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static PROCESS_ID_TYPE ap_id, per_id, nocap_id;

static SYSTEM_TIME_TYPE deadline_of(PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    return st.DEADLINE_TIME;
}

static void try_replenish(const char *check, PROCESS_ID_TYPE self, SYSTEM_TIME_TYPE budget,
                          RETURN_CODE_TYPE expect, SYSTEM_TIME_TYPE deadline)
{
    RETURN_CODE_TYPE rc;
    REPLENISH(budget, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.deadline", check);
    check_int(n, deadline, deadline_of(self));
}

static void nocap(void)
{
    /* No time capacity, no deadline: nothing to replenish. */
    try_replenish("nocap.no_action", nocap_id, 1 * MS, NO_ACTION, INFINITE_TIME_VALUE);
}

static void ap(void)
{
    /* Started at 0 with a time capacity of 5 ms. */
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(1 * MS, &rc);
    try_replenish("aperiodic", ap_id, 3 * MS, NO_ERROR, 4 * MS);
    try_replenish("aperiodic.budget_minus_2", ap_id, -2, INVALID_PARAM, 4 * MS);
    /* 1 ms + INT64_MAX is past the end of the clock. */
    try_replenish("aperiodic.budget_beyond_clock", ap_id, INT64_MAX, INVALID_PARAM, 4 * MS);
    try_replenish("aperiodic.infinite", ap_id, INFINITE_TIME_VALUE, NO_ERROR, INFINITE_TIME_VALUE);
    try_replenish("aperiodic.again", ap_id, 2 * MS, NO_ERROR, 3 * MS);
}

static void per(void)
{
    /* Released at 0 and 20 ms, time capacity 10 ms: next release point 20 ms. */
    RETURN_CODE_TYPE rc;
    check_int("periodic.release.deadline", 10 * MS, deadline_of(per_id));
    try_replenish("periodic", per_id, 5 * MS, NO_ERROR, 5 * MS);
    try_replenish("periodic.up_to_next_release", per_id, 20 * MS, NO_ERROR, 20 * MS);
    try_replenish("periodic.past_next_release", per_id, 20 * MS + 1, INVALID_MODE, 20 * MS);
    try_replenish("periodic.infinite", per_id, INFINITE_TIME_VALUE, INVALID_MODE, 20 * MS);
    try_replenish("periodic.budget_minus_2", per_id, -2, INVALID_PARAM, 20 * MS);
    PERIODIC_WAIT(&rc);
    /* A new release, a new deadline: release + time capacity. */
    check_int("periodic.next.deadline", 30 * MS, deadline_of(per_id));
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    REPLENISH(1 * MS, &rc);
    check_rc("init.no_action", NO_ACTION, rc);
    PROCESS_ATTRIBUTE_TYPE a = process_attributes("ap", ap, 20, INFINITE_TIME_VALUE, 5 * MS);
    CREATE_PROCESS(&a, &ap_id, &rc);
    setup_rc("CREATE_PROCESS ap", rc);
    a = process_attributes("per", per, 10, 20 * MS, 10 * MS);
    CREATE_PROCESS(&a, &per_id, &rc);
    setup_rc("CREATE_PROCESS per", rc);
    nocap_id = new_process("nocap", nocap, 30, INFINITE_TIME_VALUE);
    PROCESS_ID_TYPE started[] = {ap_id, per_id, nocap_id};
    for (size_t i = 0; i < sizeof started / sizeof started[0]; i++) {
        START(started[i], &rc);
        setup_rc("START", rc);
    }
    enter_normal();
    return 1;
}
