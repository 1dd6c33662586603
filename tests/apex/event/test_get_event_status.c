/* SPDX-License-Identifier: Apache-2.0 */
/* GET_EVENT_STATUS (ARINC 653 Part 1, 3.7.2.4): NO_ERROR with the event's state and the
 * number of processes waiting on it; INVALID_PARAM for an unknown identifier (output
 * untouched). The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static EVENT_ID_TYPE ev, other;

static EVENT_STATUS_TYPE status_of(EVENT_ID_TYPE id)
{
    EVENT_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_EVENT_STATUS(id, &st, &rc);
    setup_rc("GET_EVENT_STATUS", rc);
    return st;
}

static void bad_id(const char *check, EVENT_ID_TYPE id)
{
    EVENT_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_EVENT_STATUS(id, &st, &rc);
    check_rc(check, INVALID_PARAM, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.untouched", check);
    check_int(n, UNTOUCHED, st.WAITING_PROCESSES);
}

static void waiter(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_EVENT(ev, INFINITE_TIME_VALUE, &rc);
}

static void ctl(void)
{
    /* 0 ms: two processes wait on EV. */
    EVENT_STATUS_TYPE st = status_of(ev);
    check_str("normal.state", "DOWN", event_state_name(st.EVENT_STATE));
    check_int("normal.waiting", 2, st.WAITING_PROCESSES);
    RETURN_CODE_TYPE rc;
    SET_EVENT(ev, &rc);
    setup_rc("SET_EVENT", rc);
    st = status_of(ev);
    check_str("normal.set.state", "UP", event_state_name(st.EVENT_STATE));
    check_int("normal.set.waiting", 0, st.WAITING_PROCESSES);
    bad_id("normal.id_unknown", other + 1);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT EV", rc);
    CREATE_EVENT("OTHER", &other, &rc);
    setup_rc("CREATE_EVENT OTHER", rc);
    EVENT_STATUS_TYPE st = status_of(other);
    check_str("init.state", "DOWN", event_state_name(st.EVENT_STATE));
    check_int("init.waiting", 0, st.WAITING_PROCESSES);
    SET_EVENT(other, &rc);
    setup_rc("SET_EVENT", rc);
    check_str("init.set.state", "UP", event_state_name(status_of(other).EVENT_STATE));
    check_str("init.set.other_unchanged", "DOWN", event_state_name(status_of(ev).EVENT_STATE));

    bad_id("init.id_zero", 0);
    bad_id("init.id_negative", -1);
    bad_id("init.id_unknown", other + 1);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("waiter1", waiter, 20, INFINITE_TIME_VALUE);
    start_new_process("waiter2", waiter, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
