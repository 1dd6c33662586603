/* SPDX-License-Identifier: Apache-2.0 */
/* GET_QUEUING_PORT_STATUS (ARINC 653 Part 1, 3.6.2.2): NO_ERROR with NB_MESSAGE,
 * MAX_NB_MESSAGE, MAX_MESSAGE_SIZE, PORT_DIRECTION and WAITING_PROCESSES; INVALID_PARAM for
 * an unknown identifier (output untouched). "src" (window 0-5 ms of a 20 ms frame) sends on a
 * 3-message source queue until a process waits for room; "dst" (window 10-15 ms, 5-message
 * queue) empties its queue, then two processes wait for a message. */
#include "apex_check.h"

static QUEUING_PORT_ID_TYPE port;
static SAMPLING_PORT_ID_TYPE sampling;
static char r1_msg[16] = "(none)", r2_msg[16] = "(none)";

static void check_status(const char *phase, int nb, int max_nb, PORT_DIRECTION_TYPE dir,
                         int waiting)
{
    QUEUING_PORT_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_QUEUING_PORT_STATUS(port, &st, &rc);
    char n[64];
    snprintf(n, sizeof n, "%s.rc", phase);
    check_rc(n, NO_ERROR, rc);
    snprintf(n, sizeof n, "%s.nb_message", phase);
    check_int(n, nb, st.NB_MESSAGE);
    if (max_nb) {
        snprintf(n, sizeof n, "%s.max_nb_message", phase);
        check_int(n, max_nb, st.MAX_NB_MESSAGE);
        snprintf(n, sizeof n, "%s.max_message_size", phase);
        check_int(n, 16, st.MAX_MESSAGE_SIZE);
        snprintf(n, sizeof n, "%s.port_direction", phase);
        check_str(n, direction_name(dir), direction_name(st.PORT_DIRECTION));
    }
    snprintf(n, sizeof n, "%s.waiting_processes", phase);
    check_int(n, waiting, st.WAITING_PROCESSES);
}

static void bad_ids(void)
{
    QUEUING_PORT_ID_TYPE ids[] = {0, 99, sampling};
    const char *names[] = {"id_zero", "id_unknown", "sampling_port_id"};
    for (int i = 0; i < 3; i++) {
        QUEUING_PORT_STATUS_TYPE st;
        memset(&st, 0x5A, sizeof st);
        RETURN_CODE_TYPE rc;
        GET_QUEUING_PORT_STATUS(ids[i], &st, &rc);
        check_rc(names[i], INVALID_PARAM, rc);
        char n[64];
        snprintf(n, sizeof n, "%s.untouched", names[i]);
        check_int(n, UNTOUCHED, st.NB_MESSAGE);
    }
}

static RETURN_CODE_TYPE send_text(const char *text, SYSTEM_TIME_TYPE timeout)
{
    APEX_BYTE msg[16] = {0};
    snprintf((char *)msg, sizeof msg, "%s", text);
    RETURN_CODE_TYPE rc;
    SEND_QUEUING_MESSAGE(port, msg, sizeof msg, timeout, &rc);
    return rc;
}

static void tx(void)
{
    setup_rc("SEND m2", send_text("m2", 0));
    setup_rc("SEND m3", send_text("m3", INFINITE_TIME_VALUE)); /* full until 5 ms */
}

static void src_observer(void)
{
    RETURN_CODE_TYPE rc;
    check_status("src.full", 3, 0, SOURCE, 1); /* 0 ms: tx waits for room */
    PERIODIC_WAIT(&rc);
    check_status("src.later", 1, 0, SOURCE, 0); /* 20 ms: m3 went in */
}

static void src(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT("QP_OUT", 16, 3, SOURCE, FIFO, &port, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_OUT", rc);
    CREATE_SAMPLING_PORT("SP_S", 16, SOURCE, 50 * MS, &sampling, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_S", rc);
    check_status("init", 0, 3, SOURCE, 0);
    bad_ids();
    setup_rc("SEND m0", send_text("m0", 0));
    setup_rc("SEND m1", send_text("m1", 0));
    check_status("init.after_sending", 2, 0, SOURCE, 0);
    start_new_process("tx", tx, 20, INFINITE_TIME_VALUE);
    start_new_process("observer", src_observer, 10, 20 * MS);
    enter_normal();
}

static void receive_into(char *text)
{
    APEX_BYTE msg[16];
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    RECEIVE_QUEUING_MESSAGE(port, INFINITE_TIME_VALUE, msg, &len, &rc);
    setup_rc("RECEIVE_QUEUING_MESSAGE", rc);
    snprintf(text, 16, "%s", message_text(msg, len));
}

static void r1(void) { receive_into(r1_msg); }
static void r2(void) { receive_into(r2_msg); }

static void dst_observer(void)
{
    RETURN_CODE_TYPE rc;
    check_status("dst.two_waiting", 0, 0, DESTINATION, 2); /* 10 ms */
    PERIODIC_WAIT(&rc);
    /* 30 ms: m3 arrived (sent at 20 ms, moved at 25 ms); the process that waited longest
     * got it. */
    check_status("dst.one_waiting", 0, 0, DESTINATION, 1);
    check_str("dst.first_waiter_served", "m3", r1_msg);
    check_str("dst.second_waiter_waits", "(none)", r2_msg);
}

static void dst(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT("QP_IN", 16, 5, DESTINATION, FIFO, &port, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_IN", rc);
    CREATE_SAMPLING_PORT("SP_S", 16, SOURCE, 50 * MS, &sampling, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_S", rc);
    /* m0, m1 (initialisation) and m2 (tx) moved at the end of src's window. */
    check_status("init", 3, 5, DESTINATION, 0);
    bad_ids();
    for (int i = 0; i < 3; i++) {
        APEX_BYTE msg[16];
        MESSAGE_SIZE_TYPE len;
        RECEIVE_QUEUING_MESSAGE(port, 0, msg, &len, &rc);
        setup_rc("RECEIVE_QUEUING_MESSAGE", rc);
    }
    check_status("init.after_receiving", 0, 0, DESTINATION, 0);
    start_new_process("r1", r1, 20, INFINITE_TIME_VALUE);
    start_new_process("r2", r2, 20, INFINITE_TIME_VALUE);
    start_new_process("observer", dst_observer, 5, 20 * MS);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "src") == 0)
        src();
    else if (strcmp(scenario, "dst") == 0)
        dst();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
