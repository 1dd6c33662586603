/* SPDX-License-Identifier: Apache-2.0 */
/* RECEIVE_BUFFER (ARINC 653 Part 1, 3.7.2.1): every return code, from the initialisation
 * process and from processes; waiting receivers served in FIFO or priority order; a receive
 * from a full buffer takes in the first waiting sender's message and releases that sender.
 * LENGTH is 0 when no message was received and left alone on INVALID_PARAM. The partition
 * period is 20 ms; its window is the
 * first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static BUFFER_ID_TYPE rf, rp;
static EVENT_ID_TYPE ev;
static PROCESS_ID_TYPE late_sender_id;

static RETURN_CODE_TYPE send_text(BUFFER_ID_TYPE id, const char *text)
{
    RETURN_CODE_TYPE rc;
    SEND_BUFFER(id, (MESSAGE_ADDR_TYPE)text, (MESSAGE_SIZE_TYPE)strlen(text), 0, &rc);
    return rc;
}

/* Receives and checks the return code, the message ("-" if LENGTH was not written) and LENGTH
 * (the table holds the expected value: the message's length, 0, or UNTOUCHED). */
static void try_receive(const char *check, BUFFER_ID_TYPE id, SYSTEM_TIME_TYPE time_out,
                        RETURN_CODE_TYPE expect, const char *text)
{
    APEX_BYTE msg[8];
    memset(msg, 0, sizeof msg);
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    RECEIVE_BUFFER(id, time_out, msg, &len, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.message", check);
    check_str(n, expect == NO_ERROR ? text : "*", len == UNTOUCHED ? "-" : message_text(msg, len));
    snprintf(n, sizeof n, "%s.length", check);
    observe_int(n, len);
}

static void receiver(const char *name, BUFFER_ID_TYPE id, bool later)
{
    RETURN_CODE_TYPE rc;
    if (later)
        TIMED_WAIT(1 * MS, &rc);
    APEX_BYTE msg[8] = {0};
    MESSAGE_SIZE_TYPE len;
    RECEIVE_BUFFER(id, INFINITE_TIME_VALUE, msg, &len, &rc);
    setup_rc("RECEIVE_BUFFER", rc);
    char n[32];
    snprintf(n, sizeof n, "%s.received", name);
    check_str(n, "*", message_text(msg, len));
}

static void r1(void) { receiver("r1", rf, false); }
static void r2(void) { receiver("r2", rf, true); }
static void q1(void) { receiver("q1", rp, false); }
static void q2(void) { receiver("q2", rp, true); }

static void late_sender(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_EVENT(ev, INFINITE_TIME_VALUE, &rc);
    SEND_BUFFER(rf, (MESSAGE_ADDR_TYPE) "c", 1, INFINITE_TIME_VALUE, &rc);
    check_rc("late_sender.sent", NO_ERROR, rc);
}

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    /* 0 ms. Meanwhile r1 (priority 5, at 0 ms) and r2 (6, at 1 ms) wait on RF, q1 (7, at
     * 0 ms) and q2 (8, at 1 ms) on RP. */
    try_receive("normal.empty.no_wait", rf, 0, NOT_AVAILABLE, "-");
    SYSTEM_TIME_TYPE t0 = now_ns();
    try_receive("normal.empty.timed_out", rf, 2 * MS, TIMED_OUT, "-");
    check_int("normal.empty.timed_out.elapsed", 2 * MS, now_ns() - t0);
    /* 2 ms + INT64_MAX is past the end of the clock. */
    try_receive("normal.timeout_beyond_clock", rf, INT64_MAX, INVALID_PARAM, "-");

    BUFFER_STATUS_TYPE st;
    GET_BUFFER_STATUS(rf, &st, &rc);
    setup_rc("GET_BUFFER_STATUS", rc);
    check_int("normal.waiting_receivers", 2, st.WAITING_PROCESSES);
    /* FIFO: the first message to the first receiver; PRIORITY: to the highest priority. */
    send_text(rf, "f1");
    send_text(rf, "f2");
    send_text(rp, "p1");
    send_text(rp, "p2");
    TIMED_WAIT(1 * MS, &rc); /* 3 ms: they report what they got */

    /* A receive from a full buffer takes in the waiting sender's message. */
    send_text(rf, "a");
    send_text(rf, "b");
    SET_EVENT(ev, &rc);
    setup_rc("SET_EVENT", rc);
    TIMED_WAIT(1 * MS, &rc); /* 4 ms: late_sender waits to send "c" */
    check_str("normal.full.sender_waits", "WAITING", process_state_name(late_sender_id));
    try_receive("normal.full", rf, 0, NO_ERROR, "a");
    check_str("normal.full.sender_released", "READY", process_state_name(late_sender_id));
    try_receive("normal.then.0", rf, 0, NO_ERROR, "b");
    try_receive("normal.then.1", rf, INFINITE_TIME_VALUE, NO_ERROR, "c");

    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    try_receive("normal.preemption_locked", rf, 1 * MS, INVALID_MODE, "-");
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BUFFER("RF", 8, 2, FIFO, &rf, &rc);
    setup_rc("CREATE_BUFFER RF", rc);
    CREATE_BUFFER("RP", 8, 2, PRIORITY, &rp, &rc);
    setup_rc("CREATE_BUFFER RP", rc);
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT", rc);

    try_receive("init.id_zero", 0, 0, INVALID_PARAM, "-");
    try_receive("init.id_unknown", rp + 1, 0, INVALID_PARAM, "-");
    try_receive("init.timeout_minus_2", rf, -2, INVALID_PARAM, "-");
    try_receive("init.empty.no_wait", rf, 0, NOT_AVAILABLE, "-");
    /* (Null addresses: tests/apex/pointers/.) The initialisation process cannot wait. */
    try_receive("init.empty.would_wait", rf, 1 * MS, INVALID_MODE, "-");
    send_text(rf, "m1");
    try_receive("init.message", rf, INFINITE_TIME_VALUE, NO_ERROR, "m1");

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("r1", r1, 5, INFINITE_TIME_VALUE);
    start_new_process("r2", r2, 6, INFINITE_TIME_VALUE);
    start_new_process("q1", q1, 7, INFINITE_TIME_VALUE);
    start_new_process("q2", q2, 8, INFINITE_TIME_VALUE);
    late_sender_id = start_new_process("late_sender", late_sender, 4, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
