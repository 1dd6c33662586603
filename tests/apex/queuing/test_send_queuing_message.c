/* SPDX-License-Identifier: Apache-2.0 */
/* SEND_QUEUING_MESSAGE (ARINC 653 Part 1, 3.6.2.2). Scenario "sender" (window 0-5 ms of a
 * 20 ms frame; its source queue holds 4 messages and is emptied by the SKE at the end of its
 * window): every return code, from the initialisation process and from a process. Scenario
 * "receiver" (window 10-15 ms): receives exactly the messages that were sent with NO_ERROR,
 * in order. */
#include <stdint.h>

#include "apex_check.h"

static QUEUING_PORT_ID_TYPE out, lone_in, port_in;
static SAMPLING_PORT_ID_TYPE sampling;

static RETURN_CODE_TYPE send_text(QUEUING_PORT_ID_TYPE id, const char *text,
                                  MESSAGE_SIZE_TYPE len, SYSTEM_TIME_TYPE timeout)
{
    APEX_BYTE msg[32];
    memset(msg, 0, sizeof msg);
    snprintf((char *)msg, sizeof msg, "%s", text);
    RETURN_CODE_TYPE rc;
    SEND_QUEUING_MESSAGE(id, msg, len, timeout, &rc);
    return rc;
}

static void try_send(const char *check, QUEUING_PORT_ID_TYPE id, const char *text,
                     MESSAGE_SIZE_TYPE len, SYSTEM_TIME_TYPE timeout, RETURN_CODE_TYPE expect)
{
    check_rc(check, expect, send_text(id, text, len, timeout));
}

static void tx(void)
{
    /* 0 ms: the queue still holds the 4 messages of the initialisation process. */
    try_send("normal.full.no_wait", out, "lost", 16, 0, NOT_AVAILABLE);
    SYSTEM_TIME_TYPE t0 = now_ns();
    try_send("normal.full.timed_out", out, "lost", 16, 2 * MS, TIMED_OUT);
    check_int("normal.full.timed_out.elapsed", 2 * MS, now_ns() - t0);
    try_send("normal.timeout_minus_2", out, "lost", 16, -2, INVALID_PARAM);
    /* 2 ms + INT64_MAX is past the end of the clock: out of range. */
    t0 = now_ns();
    try_send("normal.timeout_beyond_clock", out, "lost", 16, INT64_MAX, INVALID_PARAM);
    check_int("normal.timeout_beyond_clock.elapsed", 0, now_ns() - t0);
    /* The SKE empties the queue at 5 ms; the sender next runs at 20 ms. */
    try_send("normal.full.wait", out, "m4", 16, INFINITE_TIME_VALUE, NO_ERROR);
    check_int("normal.full.wait.sent_at", 20 * MS, now_ns());
    try_send("normal.space", out, "m5", 16, 0, NO_ERROR);
}

static void observer(void)
{
    /* Runs while tx waits to send. */
    QUEUING_PORT_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_QUEUING_PORT_STATUS(out, &st, &rc);
    setup_rc("GET_QUEUING_PORT_STATUS", rc);
    check_int("normal.waiting_processes", 1, st.WAITING_PROCESSES);
    check_int("normal.nb_message", 4, st.NB_MESSAGE);
}

static void sender(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT("QP_OUT", 16, 4, SOURCE, FIFO, &out, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_OUT", rc);
    CREATE_QUEUING_PORT("QP_LONE_IN", 16, 4, DESTINATION, FIFO, &lone_in, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_LONE_IN", rc);
    CREATE_SAMPLING_PORT("SP_S", 16, SOURCE, 50 * MS, &sampling, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_S", rc);

    try_send("id_zero", 0, "lost", 16, 0, INVALID_PARAM);
    try_send("id_unknown", 99, "lost", 16, 0, INVALID_PARAM);
    try_send("sampling_port_id", sampling, "lost", 16, 0, INVALID_PARAM);
    try_send("length_zero", out, "lost", 0, 0, INVALID_PARAM);
    try_send("length_negative", out, "lost", -1, 0, INVALID_PARAM);
    try_send("length_over_max", out, "lost", 17, 0, INVALID_CONFIG);
    try_send("timeout_minus_2", out, "lost", 16, -2, INVALID_PARAM);
    try_send("destination_port", lone_in, "lost", 16, 0, INVALID_MODE);

    try_send("send.0", out, "m0", 16, 0, NO_ERROR);
    try_send("send.1", out, "m1", 3, 0, NO_ERROR);
    try_send("send.2", out, "m2", 16, 1 * MS, NO_ERROR);
    try_send("send.3", out, "m3", 16, INFINITE_TIME_VALUE, NO_ERROR);
    try_send("full.no_wait", out, "lost", 16, 0, NOT_AVAILABLE);
    /* The initialisation process cannot wait. */
    try_send("full.would_wait", out, "lost", 16, 1 * MS, INVALID_MODE);
    try_send("full.would_wait_forever", out, "lost", 16, INFINITE_TIME_VALUE, INVALID_MODE);

    start_new_process("tx", tx, 20, INFINITE_TIME_VALUE);
    start_new_process("observer", observer, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

static void rx(void)
{
    for (int k = 0; k < 2; k++) {
        char got[96] = "";
        RETURN_CODE_TYPE rc;
        for (;;) {
            APEX_BYTE msg[16];
            MESSAGE_SIZE_TYPE len;
            RECEIVE_QUEUING_MESSAGE(port_in, 0, msg, &len, &rc);
            if (rc != NO_ERROR)
                break;
            if (got[0])
                strcat(got, ",");
            snprintf(got + strlen(got), sizeof got - strlen(got), "%s/%d", message_text(msg, len),
                     (int)len);
        }
        char n[32];
        snprintf(n, sizeof n, "frame%d.received", k);
        check_str(n, k == 0 ? "m0/16,m1/3,m2/16,m3/16" : "m4/16,m5/16", got);
        snprintf(n, sizeof n, "frame%d.then", k);
        check_rc(n, NOT_AVAILABLE, rc);
        PERIODIC_WAIT(&rc);
    }
}

static void receiver(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT("QP_IN", 16, 8, DESTINATION, FIFO, &port_in, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_IN", rc);
    start_new_process("rx", rx, 10, 20 * MS);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "sender") == 0)
        sender();
    else if (strcmp(scenario, "receiver") == 0)
        receiver();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
