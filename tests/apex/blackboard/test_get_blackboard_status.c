/* SPDX-License-Identifier: Apache-2.0 */
/* GET_BLACKBOARD_STATUS (ARINC 653 Part 1, 3.7.2.2): NO_ERROR with the empty indicator, the
 * maximum message size and the number of processes waiting to read; INVALID_PARAM for an
 * unknown identifier (output untouched). The partition period is 20 ms; its window is the
 * first 10 ms of it. */
#include "apex_check.h"

static BLACKBOARD_ID_TYPE board, other;

static BLACKBOARD_STATUS_TYPE status_of(BLACKBOARD_ID_TYPE id)
{
    BLACKBOARD_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_BLACKBOARD_STATUS(id, &st, &rc);
    setup_rc("GET_BLACKBOARD_STATUS", rc);
    return st;
}

static void bad_id(const char *check, BLACKBOARD_ID_TYPE id)
{
    BLACKBOARD_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_BLACKBOARD_STATUS(id, &st, &rc);
    check_rc(check, INVALID_PARAM, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.untouched", check);
    check_int(n, UNTOUCHED, st.MAX_MESSAGE_SIZE);
}

static void reader(void)
{
    APEX_BYTE msg[8];
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    READ_BLACKBOARD(board, INFINITE_TIME_VALUE, msg, &len, &rc);
}

static void ctl(void)
{
    /* 0 ms: two readers wait on the empty BOARD. */
    BLACKBOARD_STATUS_TYPE st = status_of(board);
    check_str("normal.empty", "EMPTY", empty_indicator_name(st.EMPTY_INDICATOR));
    check_int("normal.waiting", 2, st.WAITING_PROCESSES);
    RETURN_CODE_TYPE rc;
    DISPLAY_BLACKBOARD(board, (MESSAGE_ADDR_TYPE) "x", 1, &rc);
    setup_rc("DISPLAY_BLACKBOARD", rc);
    st = status_of(board);
    check_str("normal.displayed", "OCCUPIED", empty_indicator_name(st.EMPTY_INDICATOR));
    check_int("normal.displayed.waiting", 0, st.WAITING_PROCESSES);
    bad_id("normal.id_unknown", other + 1);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BLACKBOARD("BOARD", 16, &board, &rc);
    setup_rc("CREATE_BLACKBOARD BOARD", rc);
    CREATE_BLACKBOARD("OTHER", 100, &other, &rc);
    setup_rc("CREATE_BLACKBOARD OTHER", rc);

    BLACKBOARD_STATUS_TYPE st = status_of(other);
    check_str("init.empty", "EMPTY", empty_indicator_name(st.EMPTY_INDICATOR));
    check_int("init.max_message_size", 100, st.MAX_MESSAGE_SIZE);
    check_int("init.waiting", 0, st.WAITING_PROCESSES);
    DISPLAY_BLACKBOARD(other, (MESSAGE_ADDR_TYPE) "x", 1, &rc);
    setup_rc("DISPLAY_BLACKBOARD", rc);
    check_str("init.displayed", "OCCUPIED", empty_indicator_name(status_of(other).EMPTY_INDICATOR));
    CLEAR_BLACKBOARD(other, &rc);
    setup_rc("CLEAR_BLACKBOARD", rc);
    check_str("init.cleared", "EMPTY", empty_indicator_name(status_of(other).EMPTY_INDICATOR));

    bad_id("init.id_zero", 0);
    bad_id("init.id_negative", -1);
    bad_id("init.id_unknown", other + 1);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("reader1", reader, 20, INFINITE_TIME_VALUE);
    start_new_process("reader2", reader, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
