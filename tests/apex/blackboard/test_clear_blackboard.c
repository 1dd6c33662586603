/* SPDX-License-Identifier: Apache-2.0 */
/* CLEAR_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): the blackboard becomes EMPTY (clearing an
 * empty one is no error); processes waiting to read go on waiting until the next display.
 * The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static BLACKBOARD_ID_TYPE board;
static PROCESS_ID_TYPE reader_id;

static void try_clear(const char *check, BLACKBOARD_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    CLEAR_BLACKBOARD(id, &rc);
    check_rc(check, expect, rc);
}

static const char *indicator(void)
{
    BLACKBOARD_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_BLACKBOARD_STATUS(board, &st, &rc);
    setup_rc("GET_BLACKBOARD_STATUS", rc);
    return empty_indicator_name(st.EMPTY_INDICATOR);
}

static RETURN_CODE_TYPE read_now(void)
{
    APEX_BYTE msg[8];
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    READ_BLACKBOARD(board, 0, msg, &len, &rc);
    return rc;
}

static void display(const char *text)
{
    RETURN_CODE_TYPE rc;
    DISPLAY_BLACKBOARD(board, (MESSAGE_ADDR_TYPE)text, (MESSAGE_SIZE_TYPE)strlen(text), &rc);
    setup_rc("DISPLAY_BLACKBOARD", rc);
}

static void reader(void)
{
    APEX_BYTE msg[8] = {0};
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    READ_BLACKBOARD(board, INFINITE_TIME_VALUE, msg, &len, &rc);
    setup_rc("READ_BLACKBOARD", rc);
    check_str("reader.got", "after", message_text(msg, len));
}

static void ctl(void)
{
    /* 0 ms: the reader (priority 20) waits on the empty blackboard. */
    try_clear("normal.reader_waiting", board, NO_ERROR);
    check_str("normal.reader_waiting.state", "WAITING", process_state_name(reader_id));
    display("after");
    check_str("normal.displayed.reader", "DORMANT", process_state_name(reader_id));
    try_clear("normal.occupied", board, NO_ERROR);
    check_rc("normal.occupied.read", NOT_AVAILABLE, read_now());
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BLACKBOARD("BOARD", 8, &board, &rc);
    setup_rc("CREATE_BLACKBOARD", rc);
    try_clear("init.id_zero", 0, INVALID_PARAM);
    try_clear("init.id_negative", -1, INVALID_PARAM);
    try_clear("init.id_unknown", board + 1, INVALID_PARAM);
    try_clear("init.empty", board, NO_ERROR);
    check_str("init.empty.indicator", "EMPTY", indicator());
    display("before");
    check_str("init.displayed.indicator", "OCCUPIED", indicator());
    try_clear("init.occupied", board, NO_ERROR);
    check_str("init.occupied.indicator", "EMPTY", indicator());
    check_rc("init.occupied.read", NOT_AVAILABLE, read_now());

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    reader_id = start_new_process("reader", reader, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
