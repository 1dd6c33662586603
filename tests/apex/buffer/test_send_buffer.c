/* SPDX-License-Identifier: Apache-2.0 */
/* SEND_BUFFER (ARINC 653 Part 1, 3.7.2.1): every return code, from the initialisation
 * process and from processes; waiting senders served in FIFO or priority order; a message
 * for a waiting receiver goes straight to it, which preempts a lower-priority sender. The
 * partition period is 20 ms; its window is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static BUFFER_ID_TYPE bf, bp, br;
static EVENT_ID_TYPE ev;

static RETURN_CODE_TYPE send_text(BUFFER_ID_TYPE id, const char *text, SYSTEM_TIME_TYPE time_out)
{
    RETURN_CODE_TYPE rc;
    SEND_BUFFER(id, (MESSAGE_ADDR_TYPE)text, (MESSAGE_SIZE_TYPE)strlen(text), time_out, &rc);
    return rc;
}

static void try_send(const char *check, BUFFER_ID_TYPE id, MESSAGE_ADDR_TYPE msg,
                     MESSAGE_SIZE_TYPE len, SYSTEM_TIME_TYPE time_out, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    SEND_BUFFER(id, msg, len, time_out, &rc);
    check_rc(check, expect, rc);
}

/* Everything in buffer id, oldest first, as "a,b,c" (in a static string). */
static const char *drain(BUFFER_ID_TYPE id)
{
    static char got[96];
    got[0] = '\0';
    for (;;) {
        APEX_BYTE msg[8] = {0};
        MESSAGE_SIZE_TYPE len;
        RETURN_CODE_TYPE rc;
        RECEIVE_BUFFER(id, 0, msg, &len, &rc);
        if (rc != NO_ERROR)
            break;
        snprintf(got + strlen(got), sizeof got - strlen(got), "%s%s", got[0] ? "," : "",
                 message_text(msg, len));
    }
    return got;
}

static BUFFER_STATUS_TYPE status_of(BUFFER_ID_TYPE id)
{
    BUFFER_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_BUFFER_STATUS(id, &st, &rc);
    setup_rc("GET_BUFFER_STATUS", rc);
    return st;
}

static void recv_hi(void)
{
    APEX_BYTE msg[8] = {0};
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    RECEIVE_BUFFER(br, INFINITE_TIME_VALUE, msg, &len, &rc);
    setup_rc("RECEIVE_BUFFER recv_hi", rc);
    trail_add("recv_hi:%s", message_text(msg, len));
}

static void sender(const char *check, BUFFER_ID_TYPE id, const char *text, bool later)
{
    RETURN_CODE_TYPE rc;
    if (later)
        TIMED_WAIT(1 * MS, &rc);
    check_rc(check, NO_ERROR, send_text(id, text, INFINITE_TIME_VALUE));
}

static void s1(void) { sender("s1.sent", bf, "s1", false); }
static void s2(void) { sender("s2.sent", bf, "s2", true); }
static void p_lo(void) { sender("p_lo.sent", bp, "pl", false); }
static void p_hi(void) { sender("p_hi.sent", bp, "ph", true); }

static void rx_late(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_EVENT(ev, INFINITE_TIME_VALUE, &rc);
    APEX_BYTE msg[8] = {0};
    MESSAGE_SIZE_TYPE len;
    RECEIVE_BUFFER(br, 0, msg, &len, &rc);
    setup_rc("RECEIVE_BUFFER rx_late", rc);
    check_str("rx_late.received", "a", message_text(msg, len));
}

static void ctl(void)
{
    /* 0 ms: recv_hi waits on the empty BR. */
    RETURN_CODE_TYPE rc;
    check_rc("normal.full.no_wait", NOT_AVAILABLE, send_text(bf, "x", 0));
    SYSTEM_TIME_TYPE t0 = now_ns();
    /* Meanwhile s1 (0 ms) then s2 (1 ms) wait to send on BF, p_lo (0 ms) then p_hi (1 ms) on
     * BP. */
    check_rc("normal.full.timed_out", TIMED_OUT, send_text(bf, "x", 2 * MS));
    check_int("normal.full.timed_out.elapsed", 2 * MS, now_ns() - t0);
    BUFFER_STATUS_TYPE st = status_of(bf);
    check_int("normal.full.nb_message", 2, st.NB_MESSAGE);
    check_int("normal.full.waiting_processes", 2, st.WAITING_PROCESSES);
    /* 2 ms + INT64_MAX is past the end of the clock. */
    check_rc("normal.timeout_beyond_clock", INVALID_PARAM, send_text(bf, "x", INT64_MAX));

    /* Each receive takes the next waiting sender's message into the buffer. */
    check_str("normal.fifo.order", "i0,i1,s1,s2", drain(bf));
    check_str("normal.priority.order", "p0,ph,pl", drain(bp));

    check_rc("normal.to_waiting_receiver", NO_ERROR, send_text(br, "hand", 0));
    trail_add("ctl");
    check_str("normal.to_waiting_receiver.preempts", "recv_hi:hand,ctl", trail);
    check_int("normal.to_waiting_receiver.not_queued", 0, status_of(br).NB_MESSAGE);

    check_rc("normal.space", NO_ERROR, send_text(br, "a", 0));
    check_rc("normal.space.infinite", NO_ERROR, send_text(br, "b", INFINITE_TIME_VALUE));

    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    check_rc("normal.preemption_locked", INVALID_MODE, send_text(br, "c", 1 * MS));
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);

    /* rx_late (priority 4) receives "a" once this process waits; "c" then goes in. */
    SET_EVENT(ev, &rc);
    setup_rc("SET_EVENT", rc);
    check_rc("normal.full.wait", NO_ERROR, send_text(br, "c", INFINITE_TIME_VALUE));
    check_str("normal.full.wait.order", "b,c", drain(br));
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BUFFER("BF", 8, 2, FIFO, &bf, &rc);
    setup_rc("CREATE_BUFFER BF", rc);
    CREATE_BUFFER("BP", 8, 1, PRIORITY, &bp, &rc);
    setup_rc("CREATE_BUFFER BP", rc);
    CREATE_BUFFER("BR", 8, 2, FIFO, &br, &rc);
    setup_rc("CREATE_BUFFER BR", rc);
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT", rc);

    APEX_BYTE big[16] = "0123456789abcde";
    try_send("init.id_zero", 0, big, 4, 0, INVALID_PARAM);
    try_send("init.id_unknown", br + 1, big, 4, 0, INVALID_PARAM);
    try_send("init.length_over_max", bf, big, 9, 0, INVALID_PARAM);
    try_send("init.length_zero", bf, big, 0, 0, INVALID_PARAM);
    try_send("init.length_negative", bf, big, -1, 0, INVALID_PARAM);
    try_send("init.timeout_minus_2", bf, big, 4, -2, INVALID_PARAM);

    check_rc("init.send.0", NO_ERROR, send_text(bf, "i0", 0));
    check_rc("init.send.1", NO_ERROR, send_text(bf, "i1", 1 * MS));
    check_rc("init.full.no_wait", NOT_AVAILABLE, send_text(bf, "x", 0));
    /* The initialisation process cannot wait. */
    check_rc("init.full.would_wait", INVALID_MODE, send_text(bf, "x", 1 * MS));
    check_rc("init.full.would_wait_forever", INVALID_MODE, send_text(bf, "x", INFINITE_TIME_VALUE));
    check_rc("init.send.bp", NO_ERROR, send_text(bp, "p0", 0));

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("recv_hi", recv_hi, 30, INFINITE_TIME_VALUE);
    start_new_process("s1", s1, 5, INFINITE_TIME_VALUE);
    start_new_process("s2", s2, 6, INFINITE_TIME_VALUE);
    start_new_process("p_lo", p_lo, 7, INFINITE_TIME_VALUE);
    start_new_process("p_hi", p_hi, 8, INFINITE_TIME_VALUE);
    start_new_process("rx_late", rx_late, 4, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
