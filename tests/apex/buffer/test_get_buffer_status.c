/* SPDX-License-Identifier: Apache-2.0 */
/* GET_BUFFER_STATUS (ARINC 653 Part 1, 3.7.2.1): NO_ERROR with the number of messages, the
 * buffer's sizes and the number of processes waiting on it (to send or to receive);
 * INVALID_PARAM for an unknown identifier (output untouched). The partition period is 20 ms;
 * its window is the first 10 ms of it. */
#include "apex_check.h"

static BUFFER_ID_TYPE one, two;

static BUFFER_STATUS_TYPE status_of(BUFFER_ID_TYPE id)
{
    BUFFER_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_BUFFER_STATUS(id, &st, &rc);
    setup_rc("GET_BUFFER_STATUS", rc);
    return st;
}

static void bad_id(const char *check, BUFFER_ID_TYPE id)
{
    BUFFER_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_BUFFER_STATUS(id, &st, &rc);
    check_rc(check, INVALID_PARAM, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.untouched", check);
    check_int(n, UNTOUCHED, st.NB_MESSAGE);
}

static void send(BUFFER_ID_TYPE id, const char *text)
{
    RETURN_CODE_TYPE rc;
    SEND_BUFFER(id, (MESSAGE_ADDR_TYPE)text, (MESSAGE_SIZE_TYPE)strlen(text), 0, &rc);
    setup_rc("SEND_BUFFER", rc);
}

static void receiver(void)
{
    APEX_BYTE msg[4];
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    RECEIVE_BUFFER(two, INFINITE_TIME_VALUE, msg, &len, &rc);
}

static void sender(void)
{
    RETURN_CODE_TYPE rc;
    SEND_BUFFER(one, (MESSAGE_ADDR_TYPE) "s", 1, INFINITE_TIME_VALUE, &rc);
}

static void ctl(void)
{
    /* 0 ms: two receivers wait on the empty TWO, two senders on the full ONE. */
    BUFFER_STATUS_TYPE st = status_of(two);
    check_int("normal.receivers.nb_message", 0, st.NB_MESSAGE);
    check_int("normal.receivers.waiting", 2, st.WAITING_PROCESSES);
    st = status_of(one);
    check_int("normal.senders.nb_message", 3, st.NB_MESSAGE);
    check_int("normal.senders.waiting", 2, st.WAITING_PROCESSES);
    send(two, "m");
    check_int("normal.one_received.waiting", 1, status_of(two).WAITING_PROCESSES);
    bad_id("normal.id_unknown", two + 1);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BUFFER("ONE", 16, 3, FIFO, &one, &rc);
    setup_rc("CREATE_BUFFER ONE", rc);
    CREATE_BUFFER("TWO", 4, 1, PRIORITY, &two, &rc);
    setup_rc("CREATE_BUFFER TWO", rc);

    BUFFER_STATUS_TYPE st = status_of(one);
    check_int("init.empty.nb_message", 0, st.NB_MESSAGE);
    check_int("init.empty.max_nb_message", 3, st.MAX_NB_MESSAGE);
    check_int("init.empty.max_message_size", 16, st.MAX_MESSAGE_SIZE);
    check_int("init.empty.waiting_processes", 0, st.WAITING_PROCESSES);
    send(one, "a");
    send(one, "bb");
    check_int("init.two_messages.nb_message", 2, status_of(one).NB_MESSAGE);
    send(one, "ccc");
    check_int("init.full.nb_message", 3, status_of(one).NB_MESSAGE);
    st = status_of(two);
    check_int("init.other.max_nb_message", 1, st.MAX_NB_MESSAGE);
    check_int("init.other.max_message_size", 4, st.MAX_MESSAGE_SIZE);

    bad_id("init.id_zero", 0);
    bad_id("init.id_negative", -1);
    bad_id("init.id_unknown", two + 1);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("receiver1", receiver, 20, INFINITE_TIME_VALUE);
    start_new_process("receiver2", receiver, 20, INFINITE_TIME_VALUE);
    start_new_process("sender1", sender, 20, INFINITE_TIME_VALUE);
    start_new_process("sender2", sender, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
