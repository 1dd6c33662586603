/* SPDX-License-Identifier: Apache-2.0 */
/* CLEAR_QUEUING_PORT (ARINC 653 Part 1, 3.6.2.2). src (window 0-4 ms of a 20 ms frame) sends
 * A, B, C on QP_OUT and F0..F3 on QP_FLOOD (its destination holds two: F2 and F3 are lost) in
 * frame 1, then D and G in frame 2. dst (window 5-9 ms) clears: NO_ERROR, the waiting messages
 * are gone and the overflow is forgotten, later messages arrive as before; INVALID_PARAM (no
 * such port) and INVALID_MODE (a source port). */
#include "apex_check.h"

static QUEUING_PORT_ID_TYPE out, flood, port_in, small, dst_out;

static void send_text(QUEUING_PORT_ID_TYPE id, const char *text)
{
    RETURN_CODE_TYPE rc;
    SEND_QUEUING_MESSAGE(id, (MESSAGE_ADDR_TYPE)text, (MESSAGE_SIZE_TYPE)strlen(text) + 1, 0, &rc);
    setup_rc("SEND_QUEUING_MESSAGE", rc);
}

static void src_process(void)
{
    RETURN_CODE_TYPE rc;
    PERIODIC_WAIT(&rc); /* frame 0 stays empty for dst's initialisation */
    send_text(out, "A");
    send_text(out, "B");
    send_text(out, "C");
    send_text(flood, "F0");
    send_text(flood, "F1");
    send_text(flood, "F2");
    send_text(flood, "F3");
    PERIODIC_WAIT(&rc);
    send_text(out, "D");
    send_text(flood, "G");
}

static MESSAGE_RANGE_TYPE waiting(QUEUING_PORT_ID_TYPE id)
{
    QUEUING_PORT_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_QUEUING_PORT_STATUS(id, &st, &rc);
    setup_rc("GET_QUEUING_PORT_STATUS", rc);
    return st.NB_MESSAGE;
}

static void try_clear(const char *check, QUEUING_PORT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    CLEAR_QUEUING_PORT(id, &rc);
    check_rc(check, expect, rc);
}

/* "<check>" is the receive's return code, "<check>.message" what it got. */
static void try_receive(const char *check, QUEUING_PORT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    APEX_BYTE msg[16] = {0};
    MESSAGE_SIZE_TYPE len = 0;
    RETURN_CODE_TYPE rc;
    RECEIVE_QUEUING_MESSAGE(id, 0, msg, &len, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.message", check);
    check_str(n, "*", message_text(msg, len));
}

static void dst_process(void)
{
    RETURN_CODE_TYPE rc;
    PERIODIC_WAIT(&rc);
    /* 25 ms: A, B, C and F0, F1 arrived when src's window ended; F2 and F3 were lost. */
    try_clear("id_zero", 0, INVALID_PARAM);
    try_clear("id_unknown", 99, INVALID_PARAM);
    try_clear("source_port", dst_out, INVALID_MODE);
    check_int("before.nb_message", 3, waiting(port_in));
    try_clear("clear", port_in, NO_ERROR);
    check_int("clear.nb_message", 0, waiting(port_in));
    try_receive("clear.receive", port_in, NOT_AVAILABLE);
    try_clear("clear.again", port_in, NO_ERROR);
    try_clear("overflowed", small, NO_ERROR);
    check_int("overflowed.nb_message", 0, waiting(small));
    PERIODIC_WAIT(&rc);
    /* 45 ms: D and G sent after the clears arrive as usual, G without the old overflow. */
    try_receive("later", port_in, NO_ERROR);
    try_receive("later.overflow_forgotten", small, NO_ERROR);
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
        CREATE_QUEUING_PORT("QP_D_OUT", 16, 4, SOURCE, FIFO, &dst_out, &rc);
        setup_rc("CREATE_QUEUING_PORT QP_D_OUT", rc);
        /* Nothing has arrived yet: clearing an empty port is no error, in any mode. */
        try_clear("init.empty", port_in, NO_ERROR);
        start_new_process("dst", dst_process, 10, 20 * MS);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    enter_normal();
    return 1;
}
