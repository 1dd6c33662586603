/* SPDX-License-Identifier: Apache-2.0 */
/* DISPLAY_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): the message replaces the previous one;
 * every process waiting to read gets it, in the order they started waiting, and those of
 * higher priority than the caller run at once. The partition period is 20 ms; its window is
 * the first 10 ms of it. */
#include "apex_check.h"

static BLACKBOARD_ID_TYPE board, board2;

static RETURN_CODE_TYPE display(BLACKBOARD_ID_TYPE id, const char *text)
{
    RETURN_CODE_TYPE rc;
    DISPLAY_BLACKBOARD(id, (MESSAGE_ADDR_TYPE)text, (MESSAGE_SIZE_TYPE)strlen(text), &rc);
    return rc;
}

static void try_display(const char *check, BLACKBOARD_ID_TYPE id, MESSAGE_ADDR_TYPE msg,
                        MESSAGE_SIZE_TYPE len, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    DISPLAY_BLACKBOARD(id, msg, len, &rc);
    check_rc(check, expect, rc);
}

static const char *read_now(BLACKBOARD_ID_TYPE id)
{
    static APEX_BYTE msg[16];
    memset(msg, 0, sizeof msg);
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    READ_BLACKBOARD(id, 0, msg, &len, &rc);
    if (rc != NO_ERROR)
        return rc_name(rc);
    static char text[48];
    snprintf(text, sizeof text, "%s/%d", message_text(msg, len), (int)len);
    return text;
}

static BLACKBOARD_STATUS_TYPE status_of(BLACKBOARD_ID_TYPE id)
{
    BLACKBOARD_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_BLACKBOARD_STATUS(id, &st, &rc);
    setup_rc("GET_BLACKBOARD_STATUS", rc);
    return st;
}

static void reader(const char *name)
{
    APEX_BYTE msg[16] = {0};
    MESSAGE_SIZE_TYPE len;
    RETURN_CODE_TYPE rc;
    READ_BLACKBOARD(board2, INFINITE_TIME_VALUE, msg, &len, &rc);
    setup_rc("READ_BLACKBOARD", rc);
    trail_add("%s:%s", name, message_text(msg, len));
}

static void r_a(void) { reader("r_a"); }
static void r_b(void) { reader("r_b"); }
static void r_c(void) { reader("r_c"); }

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(1 * MS, &rc); /* r_a, r_b (20) and r_c (5) wait on the empty BOARD2 */
    check_int("normal.waiting_before", 3, status_of(board2).WAITING_PROCESSES);
    check_rc("normal.to_waiting", NO_ERROR, display(board2, "m1"));
    trail_add("ctl");
    /* r_c has not run yet: it still gets "m1". */
    check_rc("normal.replaced", NO_ERROR, display(board2, "m2"));
    check_int("normal.waiting_after", 0, status_of(board2).WAITING_PROCESSES);
    TIMED_WAIT(1 * MS, &rc);
    check_str("normal.readers.order", "r_a:m1,r_b:m1,ctl,r_c:m1", trail);
    check_str("normal.replaced.read", "m2/2", read_now(board2));
    check_rc("normal.no_reader", NO_ERROR, display(board, "m3"));
    check_str("normal.no_reader.read", "m3/2", read_now(board));
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BLACKBOARD("BOARD", 8, &board, &rc);
    setup_rc("CREATE_BLACKBOARD BOARD", rc);
    CREATE_BLACKBOARD("BOARD2", 8, &board2, &rc);
    setup_rc("CREATE_BLACKBOARD BOARD2", rc);

    APEX_BYTE big[16] = "0123456789abcde";
    try_display("init.id_zero", 0, big, 4, INVALID_PARAM);
    try_display("init.id_unknown", board2 + 1, big, 4, INVALID_PARAM);
    try_display("init.length_over_max", board, big, 9, INVALID_PARAM);
    try_display("init.length_zero", board, big, 0, INVALID_PARAM);
    try_display("init.length_negative", board, big, -1, INVALID_PARAM);
    check_str("init.errors.still_empty", "EMPTY",
              empty_indicator_name(status_of(board).EMPTY_INDICATOR));

    check_rc("init.first", NO_ERROR, display(board, "one"));
    check_str("init.first.read", "one/3", read_now(board));
    check_str("init.first.occupied", "OCCUPIED",
              empty_indicator_name(status_of(board).EMPTY_INDICATOR));
    try_display("init.largest", board, big, 8, NO_ERROR);
    check_str("init.largest.read", "01234567/8", read_now(board));
    check_rc("init.replace", NO_ERROR, display(board, "two"));
    check_str("init.replace.read", "two/3", read_now(board));

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("r_a", r_a, 20, INFINITE_TIME_VALUE);
    start_new_process("r_b", r_b, 20, INFINITE_TIME_VALUE);
    start_new_process("r_c", r_c, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
