/* SPDX-License-Identifier: Apache-2.0 */
/* UNLOCK_PREEMPTION (ARINC 653 Part 1, 3.3.2): each call undoes one LOCK_PREEMPTION; at
 * level 0 the processes made ready meanwhile run at once, highest priority first. A process
 * that stops while holding the lock releases it. The partition period is 20 ms; its window
 * is the first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE mid_id, locker_id;
static SEMAPHORE_ID_TYPE sem;

static LOCK_LEVEL_TYPE partition_lock_level(void)
{
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    setup_rc("GET_PARTITION_STATUS", rc);
    return st.LOCK_LEVEL;
}

static void try_unlock(const char *check, RETURN_CODE_TYPE expect, LOCK_LEVEL_TYPE level_expect)
{
    LOCK_LEVEL_TYPE level = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    UNLOCK_PREEMPTION(&level, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.level", check);
    check_int(n, level_expect, level);
}

static void high(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_SEMAPHORE(sem, INFINITE_TIME_VALUE, &rc);
    trail_add("high");
}

static void mid(void)
{
    RETURN_CODE_TYPE rc;
    SUSPEND_SELF(INFINITE_TIME_VALUE, &rc);
    trail_add("mid");
}

static void locker(void)
{
    LOCK_LEVEL_TYPE level;
    RETURN_CODE_TYPE rc;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    /* Returns, and so stops, with preemption locked. */
}

static void p(void)
{
    /* 0 ms: high waits on the semaphore, mid has suspended itself. */
    RETURN_CODE_TYPE rc;
    try_unlock("normal.not_locked", NO_ACTION, UNTOUCHED);
    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    SIGNAL_SEMAPHORE(sem, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
    RESUME(mid_id, &rc);
    setup_rc("RESUME", rc);
    try_unlock("normal.nested", NO_ERROR, 1);
    trail_add("p1");
    try_unlock("normal.last", NO_ERROR, 0);
    trail_add("p0");
    check_str("normal.last.order", "p1,high,mid,p0", trail);
    check_int("normal.last.partition_status", 0, partition_lock_level());

    START(locker_id, &rc); /* priority 30: runs at once */
    setup_rc("START locker", rc);
    check_int("normal.stop_self_unlocks", 0, partition_lock_level());
    try_unlock("normal.after_stop_self", NO_ACTION, UNTOUCHED);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    try_unlock("init.no_action", NO_ACTION, UNTOUCHED);
    CREATE_SEMAPHORE("SEM", 0, 1, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE", rc);
    start_new_process("p", p, 5, INFINITE_TIME_VALUE);
    start_new_process("high", high, 20, INFINITE_TIME_VALUE);
    mid_id = start_new_process("mid", mid, 10, INFINITE_TIME_VALUE);
    locker_id = new_process("locker", locker, 30, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
