/* SPDX-License-Identifier: Apache-2.0 */
/* SET_EVENT (ARINC 653 Part 1, 3.7.2.4): the event goes UP and every waiting process is
 * released, in the order they started waiting; those of higher priority than the caller
 * run at once. The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static EVENT_ID_TYPE ev, ev2;

static void try_set(const char *check, EVENT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    SET_EVENT(id, &rc);
    check_rc(check, expect, rc);
}

static EVENT_STATUS_TYPE status_of(EVENT_ID_TYPE id)
{
    EVENT_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_EVENT_STATUS(id, &st, &rc);
    setup_rc("GET_EVENT_STATUS", rc);
    return st;
}

static void waiter(const char *name, SYSTEM_TIME_TYPE time_out)
{
    RETURN_CODE_TYPE rc;
    WAIT_EVENT(ev2, time_out, &rc);
    char n[32];
    snprintf(n, sizeof n, "%s.rc", name);
    check_rc(n, NO_ERROR, rc);
    trail_add("%s", name);
}

static void w_a(void) { waiter("w_a", INFINITE_TIME_VALUE); }
static void w_b(void) { waiter("w_b", INFINITE_TIME_VALUE); }
static void w_c(void) { waiter("w_c", 5 * MS); }

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(1 * MS, &rc); /* w_a, w_b (20) and w_c (5, with a 5 ms time-out) wait */
    check_int("normal.waiting_before", 3, status_of(ev2).WAITING_PROCESSES);
    try_set("normal.waiters", ev2, NO_ERROR);
    trail_add("ctl");
    EVENT_STATUS_TYPE st = status_of(ev2);
    check_str("normal.waiters.state", "UP", event_state_name(st.EVENT_STATE));
    check_int("normal.waiting_after", 0, st.WAITING_PROCESSES);
    TIMED_WAIT(8 * MS, &rc); /* past w_c's time-out */
    check_str("normal.order", "w_a,w_b,ctl,w_c", trail);
    WAIT_EVENT(ev2, 0, &rc);
    check_rc("normal.stays_up", NO_ERROR, rc);
    try_set("normal.id_unknown", ev2 + 1, INVALID_PARAM);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT EV", rc);
    CREATE_EVENT("EV2", &ev2, &rc);
    setup_rc("CREATE_EVENT EV2", rc);
    try_set("init.id_zero", 0, INVALID_PARAM);
    try_set("init.id_negative", -1, INVALID_PARAM);
    try_set("init.id_unknown", ev2 + 1, INVALID_PARAM);
    try_set("init.down", ev, NO_ERROR);
    check_str("init.down.state", "UP", event_state_name(status_of(ev).EVENT_STATE));
    try_set("init.up", ev, NO_ERROR);
    check_str("init.up.state", "UP", event_state_name(status_of(ev).EVENT_STATE));

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("w_a", w_a, 20, INFINITE_TIME_VALUE);
    start_new_process("w_b", w_b, 20, INFINITE_TIME_VALUE);
    start_new_process("w_c", w_c, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
