/* SPDX-License-Identifier: Apache-2.0 */
/* DELAYED_START (ARINC 653 Part 1, 3.3.2): an aperiodic process is released DELAY_TIME after
 * the call (after the entry into NORMAL mode when called during initialisation), with its
 * deadline counted from there; a periodic one DELAY_TIME after the partition's next period
 * start, then every period; a zero delay is START. The partition period is 20 ms; its window
 * is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static PROCESS_ID_TYPE ctl_id, init_ap_id, per_id, ap2_id, zero_id, huge_id, per2_id, never_id;
static SYSTEM_TIME_TYPE init_ap_at = -1, ap2_at = -1, per2_at = -1, per_at[2] = {-1, -1};

static void try_delayed(const char *check, PROCESS_ID_TYPE id, SYSTEM_TIME_TYPE delay,
                        RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    DELAYED_START(id, delay, &rc);
    check_rc(check, expect, rc);
}

static void init_ap(void) { init_ap_at = now_ns(); }
static void ap2(void) { ap2_at = now_ns(); }
static void per2(void) { per2_at = now_ns(); }
static void zero(void) { trail_add("zero"); }
static void never_body(void) {}

static void per(void)
{
    for (int k = 0; k < 2; k++) {
        RETURN_CODE_TYPE rc;
        per_at[k] = now_ns();
        PERIODIC_WAIT(&rc);
    }
}

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    /* 0 ms */
    try_delayed("normal.self_running", ctl_id, 1 * MS, NO_ACTION);

    try_delayed("normal.aperiodic", ap2_id, 2 * MS, NO_ERROR);
    PROCESS_STATUS_TYPE st;
    GET_PROCESS_STATUS(ap2_id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    check_str("normal.aperiodic.state", "WAITING", state_name(st.PROCESS_STATE));
    check_int("normal.aperiodic.deadline", 2 * MS + 5 * MS, st.DEADLINE_TIME);

    try_delayed("normal.zero", zero_id, 0, NO_ERROR);
    trail_add("ctl");
    check_str("normal.zero.preempts", "zero,ctl", trail);

    /* now + DELAY_TIME + TIME_CAPACITY cannot be represented. */
    try_delayed("normal.deadline_out_of_range", huge_id, 1 * MS, INVALID_CONFIG);

    TIMED_WAIT(1 * MS, &rc);
    /* 1 ms: 1 ms + INT64_MAX is past the end of the clock. */
    try_delayed("normal.delay_beyond_clock", never_id, INT64_MAX, INVALID_PARAM);
    try_delayed("normal.periodic", per2_id, 5 * MS, NO_ERROR);

    TIMED_WAIT(27 * MS, &rc); /* to 28 ms, in the second window */
    check_int("init.aperiodic.released_at", 3 * MS, init_ap_at);
    check_int("init.periodic.released_at", 4 * MS, per_at[0]);
    check_int("init.periodic.next_release", 24 * MS, per_at[1]);
    check_int("normal.aperiodic.released_at", 2 * MS, ap2_at);
    /* Started at 1 ms: the next period starts at 20 ms. */
    check_int("normal.periodic.released_at", 25 * MS, per2_at);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    ctl_id = new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    init_ap_id = new_process("init_ap", init_ap, 15, INFINITE_TIME_VALUE);
    per_id = new_process("per", per, 25, 20 * MS);
    PROCESS_ATTRIBUTE_TYPE a = process_attributes("ap2", ap2, 20, INFINITE_TIME_VALUE, 5 * MS);
    CREATE_PROCESS(&a, &ap2_id, &rc);
    setup_rc("CREATE_PROCESS ap2", rc);
    zero_id = new_process("zero", zero, 30, INFINITE_TIME_VALUE);
    a = process_attributes("huge", never_body, 1, INFINITE_TIME_VALUE, INT64_MAX);
    CREATE_PROCESS(&a, &huge_id, &rc);
    setup_rc("CREATE_PROCESS huge", rc);
    per2_id = new_process("per2", per2, 22, 20 * MS);
    never_id = new_process("never", never_body, 1, INFINITE_TIME_VALUE);

    try_delayed("init.id_zero", 0, 1 * MS, INVALID_PARAM);
    try_delayed("init.id_unknown", never_id + 1, 1 * MS, INVALID_PARAM);
    try_delayed("init.delay_negative", never_id, -5, INVALID_PARAM);
    try_delayed("init.delay_infinite", never_id, INFINITE_TIME_VALUE, INVALID_PARAM);
    try_delayed("init.periodic.delay_period", per_id, 20 * MS, INVALID_PARAM);
    try_delayed("init.periodic.delay_above_period", per_id, 25 * MS, INVALID_PARAM);

    try_delayed("init.aperiodic", init_ap_id, 3 * MS, NO_ERROR);
    check_str("init.aperiodic.state", "WAITING", process_state_name(init_ap_id));
    try_delayed("init.already_started", init_ap_id, 1 * MS, NO_ACTION);
    try_delayed("init.periodic", per_id, 4 * MS, NO_ERROR);

    START(ctl_id, &rc);
    setup_rc("START ctl", rc);
    enter_normal();
    return 1;
}
