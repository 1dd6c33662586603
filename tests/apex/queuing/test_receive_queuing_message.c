/* SPDX-License-Identifier: Apache-2.0 */
/* RECEIVE_QUEUING_MESSAGE (ARINC 653 Part 1, 3.6.2.2). The source partition "src" has two
 * windows per 20 ms frame, A (0-4 ms) and B (10-14 ms); the destination "dst" one, 5-9 ms.
 * src sends "A<k>" in window A and "B<k>" in window B of frame k on QP_OUT, and in frame 0
 * four messages on QP_FLOOD, whose destination queue holds two. dst checks every return code:
 * NO_ERROR, NOT_AVAILABLE, TIMED_OUT, INVALID_PARAM, INVALID_MODE (source port; the
 * initialisation process would have to wait), and INVALID_CONFIG after an overflow, with the
 * message still delivered. When no message is received (NOT_AVAILABLE, TIMED_OUT, a wait
 * refused) LENGTH is 0; on INVALID_PARAM and for a source port the outputs are left alone. */
#include <stdint.h>

#include "apex_check.h"

static QUEUING_PORT_ID_TYPE out, flood, port_in, small, lone, dst_out;

static QUEUING_PORT_STATUS_TYPE status_of(QUEUING_PORT_ID_TYPE id)
{
    QUEUING_PORT_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_QUEUING_PORT_STATUS(id, &st, &rc);
    setup_rc("GET_QUEUING_PORT_STATUS", rc);
    return st;
}

static void send_text(QUEUING_PORT_ID_TYPE id, const char *text)
{
    APEX_BYTE msg[16] = {0};
    snprintf((char *)msg, sizeof msg, "%s", text);
    RETURN_CODE_TYPE rc;
    SEND_QUEUING_MESSAGE(id, msg, (MESSAGE_SIZE_TYPE)strlen(text) + 1, 0, &rc);
    setup_rc("SEND_QUEUING_MESSAGE", rc);
}

static void src_process(void)
{
    for (int k = 0; k < 3; k++) {
        char text[8];
        RETURN_CODE_TYPE rc;
        snprintf(text, sizeof text, "A%d", k);
        send_text(out, text);
        if (k == 0)
            for (int i = 0; i < 4; i++) {
                snprintf(text, sizeof text, "F%d", i);
                send_text(flood, text);
            }
        TIMED_WAIT(10 * MS, &rc); /* to window B */
        if (k == 0)
            /* The SKE took A0 from the source queue at the end of window A. */
            check_int("src.nb_message.after_window_a", 0, status_of(out).NB_MESSAGE);
        snprintf(text, sizeof text, "B%d", k);
        send_text(out, text);
        if (k == 0)
            check_int("src.nb_message.in_window_b", 1, status_of(out).NB_MESSAGE);
        PERIODIC_WAIT(&rc);
    }
}

/* Receives and checks the return code, the length and the message; a receive that gets no
 * message reports which outputs it wrote ("LENGTH=<n>", "MESSAGE", or "none"). */
static void try_receive(const char *check, QUEUING_PORT_ID_TYPE id, SYSTEM_TIME_TYPE timeout,
                        RETURN_CODE_TYPE expect, const char *text)
{
    APEX_BYTE msg[16];
    memset(msg, 0x5A, sizeof msg);
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    char n[64];
    RECEIVE_QUEUING_MESSAGE(id, timeout, msg, &len, &rc);
    check_rc(check, expect, rc);
    if (text) {
        snprintf(n, sizeof n, "%s.message", check);
        check_str(n, text, len == UNTOUCHED ? "(untouched)" : message_text(msg, len));
        snprintf(n, sizeof n, "%s.length", check);
        check_int(n, (long long)strlen(text) + 1, len);
    } else {
        bool buffer_touched = false;
        for (size_t i = 0; i < sizeof msg; i++)
            buffer_touched |= msg[i] != 0x5A;
        snprintf(n, sizeof n, "%s.outputs_written", check);
        char written[48] = "";
        if (len != UNTOUCHED)
            snprintf(written, sizeof written, "LENGTH=%d,", (int)len);
        if (buffer_touched)
            strcat(written, "MESSAGE,");
        check_str(n, "*", written[0] ? written : "none");
    }
}

static void rx(void)
{
    /* 5 ms: A0 has arrived (sent in window A, moved when it ended), B0 is not sent yet. */
    try_receive("id_zero", 0, 0, INVALID_PARAM, NULL);
    try_receive("id_unknown", 99, 0, INVALID_PARAM, NULL);
    try_receive("timeout_minus_2", port_in, -2, INVALID_PARAM, NULL);
    try_receive("source_port", dst_out, 0, INVALID_MODE, NULL);
    check_int("nb_message", 1, status_of(port_in).NB_MESSAGE);
    try_receive("received", port_in, 0, NO_ERROR, "A0");
    try_receive("empty.no_wait", port_in, 0, NOT_AVAILABLE, NULL);
    SYSTEM_TIME_TYPE t0 = now_ns();
    try_receive("empty.timed_out", port_in, 1 * MS, TIMED_OUT, NULL);
    check_int("empty.timed_out.elapsed", 1 * MS, now_ns() - t0);
    /* 6 ms + INT64_MAX is past the end of the clock: out of range. */
    t0 = now_ns();
    try_receive("timeout_beyond_clock", port_in, INT64_MAX, INVALID_PARAM, NULL);
    check_int("timeout_beyond_clock.elapsed", 0, now_ns() - t0);

    /* F0..F3 were sent; the destination queue holds two: F2 and F3 were lost. */
    try_receive("overflow", small, 0, INVALID_CONFIG, "F0");
    try_receive("overflow.next", small, 0, NO_ERROR, "F1");
    try_receive("overflow.lost", small, 0, NOT_AVAILABLE, NULL);

    /* B0 leaves the source at the end of window B (14 ms); dst next runs at 25 ms. */
    try_receive("wait", port_in, INFINITE_TIME_VALUE, NO_ERROR, "B0");
    check_int("wait.received_at", 25 * MS, now_ns());
    try_receive("wait.next", port_in, 0, NO_ERROR, "A1");
    try_receive("wait.then", port_in, 0, NOT_AVAILABLE, NULL);
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    RETURN_CODE_TYPE rc;
    if (strcmp(scenario, "src") == 0) {
        CREATE_QUEUING_PORT("QP_OUT", 16, 8, SOURCE, FIFO, &out, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_OUT", rc);
        CREATE_QUEUING_PORT("QP_FLOOD", 16, 8, SOURCE, FIFO, &flood, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_FLOOD", rc);
        start_new_process("src", src_process, 10, 20 * MS);
    } else if (strcmp(scenario, "dst") == 0) {
        CREATE_QUEUING_PORT("QP_IN", 16, 8, DESTINATION, FIFO, &port_in, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_IN", rc);
        CREATE_QUEUING_PORT("QP_SMALL", 16, 2, DESTINATION, FIFO, &small, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_SMALL", rc);
        CREATE_QUEUING_PORT("QP_LONE", 16, 4, DESTINATION, FIFO, &lone, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_LONE", rc);
        CREATE_QUEUING_PORT("QP_D_OUT", 16, 4, SOURCE, FIFO, &dst_out, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_D_OUT", rc);
        /* The initialisation process cannot wait. */
        try_receive("init.empty.would_wait", lone, 1 * MS, INVALID_MODE, NULL);
        try_receive("init.empty.would_wait_forever", lone, INFINITE_TIME_VALUE, INVALID_MODE, NULL);
        try_receive("init.empty.no_wait", lone, 0, NOT_AVAILABLE, NULL);
        start_new_process("rx", rx, 10, INFINITE_TIME_VALUE);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    enter_normal();
    return 1;
}
