/* SPDX-License-Identifier: Apache-2.0 */
/* RESUME (ARINC 653 Part 1, 3.3.2): a suspended process that waits for nothing else becomes
 * ready, at once ahead of a lower-priority caller; one that still waits (its delay not yet
 * over) goes on waiting. The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE ctl_id, high_id, sleeper_id, idle_id, cyclic_id, never_id;
static SYSTEM_TIME_TYPE sleeper_woke = -1;

static void try_resume(const char *check, PROCESS_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    RESUME(id, &rc);
    check_rc(check, expect, rc);
}

static void never_body(void) {}
static void idle(void) { trail_add("idle"); }

static void high(void)
{
    RETURN_CODE_TYPE rc;
    SUSPEND_SELF(INFINITE_TIME_VALUE, &rc);
    check_rc("high.suspend_self", NO_ERROR, rc);
    trail_add("high");
}

static void sleeper(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
    sleeper_woke = now_ns();
}

static void cyclic(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        PERIODIC_WAIT(&rc);
    }
}

static void ctl(void)
{
    /* 0 ms: high has suspended itself, sleeper waits until 5 ms, idle (priority 5) is ready. */
    RETURN_CODE_TYPE rc;
    try_resume("normal.self", ctl_id, INVALID_PARAM);
    try_resume("normal.id_unknown", never_id + 1, INVALID_PARAM);
    try_resume("normal.dormant", never_id, INVALID_MODE);
    try_resume("normal.periodic", cyclic_id, INVALID_MODE);
    try_resume("normal.not_suspended", idle_id, NO_ACTION);
    try_resume("normal.waiting_not_suspended", sleeper_id, NO_ACTION);

    try_resume("normal.suspended", high_id, NO_ERROR);
    trail_add("ctl");
    check_str("normal.suspended.preempts", "high,ctl", trail);

    SUSPEND(sleeper_id, &rc);
    setup_rc("SUSPEND sleeper", rc);
    try_resume("normal.suspended_while_waiting", sleeper_id, NO_ERROR);
    check_str("normal.suspended_while_waiting.state", "WAITING", process_state_name(sleeper_id));
    try_resume("normal.resumed_already", sleeper_id, NO_ACTION);

    SUSPEND(idle_id, &rc);
    setup_rc("SUSPEND idle", rc);
    try_resume("normal.lower_priority", idle_id, NO_ERROR);
    trail_reset();
    trail_add("ctl");
    TIMED_WAIT(6 * MS, &rc);
    check_str("normal.lower_priority.runs_later", "ctl,idle", trail);
    check_int("normal.suspended_while_waiting.woke_at", 5 * MS, sleeper_woke);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    ctl_id = new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    high_id = new_process("high", high, 20, INFINITE_TIME_VALUE);
    sleeper_id = new_process("sleeper", sleeper, 15, INFINITE_TIME_VALUE);
    idle_id = new_process("idle", idle, 5, INFINITE_TIME_VALUE);
    cyclic_id = new_process("cyclic", cyclic, 30, 20 * MS);
    never_id = new_process("never", never_body, 1, INFINITE_TIME_VALUE);

    try_resume("init.id_zero", 0, INVALID_PARAM);
    try_resume("init.id_negative", -1, INVALID_PARAM);
    try_resume("init.dormant", never_id, INVALID_MODE);

    PROCESS_ID_TYPE started[] = {ctl_id, high_id, sleeper_id, idle_id, cyclic_id};
    for (size_t i = 0; i < sizeof started / sizeof started[0]; i++) {
        START(started[i], &rc);
        setup_rc("START", rc);
    }
    enter_normal();
    return 1;
}
