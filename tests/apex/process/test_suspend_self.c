/* SPDX-License-Identifier: Apache-2.0 */
/* SUSPEND_SELF (ARINC 653 Part 1, 3.3.2): the caller waits until RESUME (NO_ERROR) or its
 * time-out (TIMED_OUT); a zero time-out returns at once. Refused (INVALID_MODE) to the
 * initialisation process, to a periodic process and while preemption is locked. The
 * partition period is 20 ms; its window is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static PROCESS_ID_TYPE self_id;
static int waiting_seen;

static void try_suspend_self(const char *check, SYSTEM_TIME_TYPE time_out, RETURN_CODE_TYPE expect,
                             SYSTEM_TIME_TYPE elapsed)
{
    RETURN_CODE_TYPE rc;
    SYSTEM_TIME_TYPE t0 = now_ns();
    SUSPEND_SELF(time_out, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.elapsed", check);
    check_int(n, elapsed, now_ns() - t0);
}

static void self(void)
{
    /* 0 ms */
    try_suspend_self("normal.zero", 0, NO_ERROR, 0);
    try_suspend_self("normal.timeout_minus_2", -2, INVALID_PARAM, 0);
    try_suspend_self("normal.timed_out", 2 * MS, TIMED_OUT, 2 * MS);
    /* 2 ms: 2 ms + INT64_MAX is past the end of the clock. */
    try_suspend_self("normal.timeout_beyond_clock", INT64_MAX, INVALID_PARAM, 0);

    RETURN_CODE_TYPE rc;
    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    try_suspend_self("normal.preemption_locked", 1 * MS, INVALID_MODE, 0);
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);

    /* The resumer resumes this process at 5 ms, then at 6 ms. */
    try_suspend_self("normal.resumed", INFINITE_TIME_VALUE, NO_ERROR, 3 * MS);
    try_suspend_self("normal.resumed_before_time_out", 8 * MS, NO_ERROR, 1 * MS);
    check_int("normal.waiting_seen", 2, waiting_seen);
}

static void resumer(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
    waiting_seen += strcmp(process_state_name(self_id), "WAITING") == 0;
    RESUME(self_id, &rc);
    check_rc("resumer.resume", NO_ERROR, rc);
    TIMED_WAIT(1 * MS, &rc);
    waiting_seen += strcmp(process_state_name(self_id), "WAITING") == 0;
    RESUME(self_id, &rc);
    check_rc("resumer.resume_before_time_out", NO_ERROR, rc);
}

static void cyclic(void)
{
    RETURN_CODE_TYPE rc;
    SUSPEND_SELF(1 * MS, &rc);
    check_rc("periodic.invalid_mode", INVALID_MODE, rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    SUSPEND_SELF(1 * MS, &rc);
    check_rc("init.invalid_mode", INVALID_MODE, rc);
    SUSPEND_SELF(0, &rc);
    check_rc("init.zero.invalid_mode", INVALID_MODE, rc);
    self_id = start_new_process("self", self, 20, INFINITE_TIME_VALUE);
    start_new_process("resumer", resumer, 10, INFINITE_TIME_VALUE);
    start_new_process("cyclic", cyclic, 5, 20 * MS);
    enter_normal();
    return 1;
}
