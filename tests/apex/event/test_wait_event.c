/* SPDX-License-Identifier: Apache-2.0 */
/* WAIT_EVENT (ARINC 653 Part 1, 3.7.2.4): every return code, from the initialisation process
 * and from a process. The partition period is 20 ms; its window is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static EVENT_ID_TYPE ev;

static void try_wait(const char *check, EVENT_ID_TYPE id, SYSTEM_TIME_TYPE time_out,
                     RETURN_CODE_TYPE expect, SYSTEM_TIME_TYPE elapsed)
{
    RETURN_CODE_TYPE rc;
    SYSTEM_TIME_TYPE t0 = now_ns();
    WAIT_EVENT(id, time_out, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.elapsed", check);
    check_int(n, elapsed, now_ns() - t0);
}

static void setter(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
    SET_EVENT(ev, &rc);
    setup_rc("SET_EVENT", rc);
}

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    /* 0 ms: DOWN. */
    try_wait("normal.down.no_wait", ev, 0, NOT_AVAILABLE, 0);
    try_wait("normal.down.timed_out", ev, 2 * MS, TIMED_OUT, 2 * MS);
    /* 2 ms + INT64_MAX is past the end of the clock. */
    try_wait("normal.timeout_beyond_clock", ev, INT64_MAX, INVALID_PARAM, 0);
    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    try_wait("normal.preemption_locked", ev, 1 * MS, INVALID_MODE, 0);
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);
    /* The setter (priority 5) sets the event at 5 ms. */
    try_wait("normal.down.wait", ev, INFINITE_TIME_VALUE, NO_ERROR, 3 * MS);
    try_wait("normal.up", ev, 1 * MS, NO_ERROR, 0);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT", rc);
    try_wait("init.id_zero", 0, 0, INVALID_PARAM, 0);
    try_wait("init.id_unknown", ev + 1, 0, INVALID_PARAM, 0);
    try_wait("init.timeout_minus_2", ev, -2, INVALID_PARAM, 0);
    try_wait("init.down.no_wait", ev, 0, NOT_AVAILABLE, 0);
    /* The initialisation process cannot wait. */
    try_wait("init.down.would_wait", ev, 1 * MS, INVALID_MODE, 0);
    try_wait("init.down.would_wait_forever", ev, INFINITE_TIME_VALUE, INVALID_MODE, 0);
    SET_EVENT(ev, &rc);
    setup_rc("SET_EVENT", rc);
    try_wait("init.up", ev, 0, NO_ERROR, 0);
    try_wait("init.up.infinite", ev, INFINITE_TIME_VALUE, NO_ERROR, 0);
    RESET_EVENT(ev, &rc);
    setup_rc("RESET_EVENT", rc);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("setter", setter, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
