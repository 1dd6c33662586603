/* SPDX-License-Identifier: Apache-2.0 */
/* RESET_EVENT (ARINC 653 Part 1, 3.7.2.4): the event goes DOWN (already DOWN included);
 * processes then wait on it until the next SET_EVENT. The partition period is 20 ms; its
 * window is the first 10 ms of it. */
#include "apex_check.h"

static EVENT_ID_TYPE ev;
static PROCESS_ID_TYPE waiter_id;

static void try_reset(const char *check, EVENT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    RESET_EVENT(id, &rc);
    check_rc(check, expect, rc);
}

static const char *state(void)
{
    EVENT_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_EVENT_STATUS(ev, &st, &rc);
    setup_rc("GET_EVENT_STATUS", rc);
    return event_state_name(st.EVENT_STATE);
}

static void set(void)
{
    RETURN_CODE_TYPE rc;
    SET_EVENT(ev, &rc);
    setup_rc("SET_EVENT", rc);
}

static void waiter(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_EVENT(ev, INFINITE_TIME_VALUE, &rc);
    check_rc("waiter.rc", NO_ERROR, rc);
}

static void ctl(void)
{
    /* 0 ms: the waiter (priority 20) waits on the DOWN event. */
    RETURN_CODE_TYPE rc;
    try_reset("normal.waiter", ev, NO_ERROR);
    check_str("normal.waiter.state", "WAITING", process_state_name(waiter_id));
    set();
    check_str("normal.set.waiter", "DORMANT", process_state_name(waiter_id));
    try_reset("normal.up", ev, NO_ERROR);
    check_str("normal.up.state", "DOWN", state());
    WAIT_EVENT(ev, 0, &rc);
    check_rc("normal.up.wait", NOT_AVAILABLE, rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT", rc);
    try_reset("init.id_zero", 0, INVALID_PARAM);
    try_reset("init.id_negative", -1, INVALID_PARAM);
    try_reset("init.id_unknown", ev + 1, INVALID_PARAM);
    try_reset("init.down", ev, NO_ERROR);
    check_str("init.down.state", "DOWN", state());
    set();
    try_reset("init.up", ev, NO_ERROR);
    check_str("init.up.state", "DOWN", state());
    WAIT_EVENT(ev, 0, &rc);
    check_rc("init.up.wait", NOT_AVAILABLE, rc);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    waiter_id = start_new_process("waiter", waiter, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
