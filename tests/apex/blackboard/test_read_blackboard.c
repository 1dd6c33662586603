/* SPDX-License-Identifier: Apache-2.0 */
/* READ_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): every return code, from the initialisation
 * process and from a process; the message stays displayed after a read; LENGTH is 0 when no
 * message was read (empty, wait refused, timed out) and left alone on INVALID_PARAM. The
 * partition period is 20 ms; its window is the first 10 ms of
 * it. */
#include <stdint.h>

#include "apex_check.h"

static BLACKBOARD_ID_TYPE board, empty_board;

static void try_read(const char *check, BLACKBOARD_ID_TYPE id, SYSTEM_TIME_TYPE time_out,
                     RETURN_CODE_TYPE expect, const char *text)
{
    APEX_BYTE msg[16];
    memset(msg, 0, sizeof msg);
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    READ_BLACKBOARD(id, time_out, msg, &len, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.message", check);
    check_str(n, expect == NO_ERROR ? text : "*", len == UNTOUCHED ? "-" : message_text(msg, len));
    snprintf(n, sizeof n, "%s.length", check);
    observe_int(n, len); /* the table: the message's length, 0, or UNTOUCHED */
}

static void displayer(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
    DISPLAY_BLACKBOARD(empty_board, (MESSAGE_ADDR_TYPE) "late", 4, &rc);
    setup_rc("DISPLAY_BLACKBOARD", rc);
}

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    /* 0 ms */
    try_read("normal.occupied", board, 0, NO_ERROR, "hello");
    try_read("normal.empty.no_wait", empty_board, 0, NOT_AVAILABLE, "-");
    SYSTEM_TIME_TYPE t0 = now_ns();
    try_read("normal.empty.timed_out", empty_board, 2 * MS, TIMED_OUT, "-");
    check_int("normal.empty.timed_out.elapsed", 2 * MS, now_ns() - t0);
    /* 2 ms + INT64_MAX is past the end of the clock. */
    try_read("normal.timeout_beyond_clock", empty_board, INT64_MAX, INVALID_PARAM, "-");

    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    try_read("normal.preemption_locked", empty_board, 1 * MS, INVALID_MODE, "-");
    try_read("normal.preemption_locked.occupied", board, 1 * MS, NO_ERROR, "hello");
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);

    t0 = now_ns();
    /* The displayer (priority 5) displays "late" at 5 ms. */
    try_read("normal.empty.wait", empty_board, INFINITE_TIME_VALUE, NO_ERROR, "late");
    check_int("normal.empty.wait.elapsed", 3 * MS, now_ns() - t0);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_BLACKBOARD("BOARD", 16, &board, &rc);
    setup_rc("CREATE_BLACKBOARD BOARD", rc);
    CREATE_BLACKBOARD("EMPTY_BOARD", 16, &empty_board, &rc);
    setup_rc("CREATE_BLACKBOARD EMPTY_BOARD", rc);

    try_read("init.id_zero", 0, 0, INVALID_PARAM, "-");
    try_read("init.id_unknown", empty_board + 1, 0, INVALID_PARAM, "-");
    try_read("init.timeout_minus_2", board, -2, INVALID_PARAM, "-");
    try_read("init.empty.no_wait", board, 0, NOT_AVAILABLE, "-");
    /* (Null addresses: tests/apex/pointers/.) The initialisation process cannot wait. */
    try_read("init.empty.would_wait", board, 1 * MS, INVALID_MODE, "-");
    try_read("init.empty.would_wait_forever", board, INFINITE_TIME_VALUE, INVALID_MODE, "-");
    DISPLAY_BLACKBOARD(board, (MESSAGE_ADDR_TYPE) "hello", 5, &rc);
    setup_rc("DISPLAY_BLACKBOARD", rc);
    try_read("init.occupied", board, 0, NO_ERROR, "hello");
    try_read("init.occupied.again", board, INFINITE_TIME_VALUE, NO_ERROR, "hello");

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("displayer", displayer, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
