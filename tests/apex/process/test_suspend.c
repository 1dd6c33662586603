/* SPDX-License-Identifier: Apache-2.0 */
/* SUSPEND (ARINC 653 Part 1, 3.3.2): a suspended process is WAITING and does not run until
 * RESUME; one suspended while it waits keeps waiting (its time-out runs, a semaphore can be
 * given to it) and stays WAITING when that wait ends. The partition period is 20 ms; its
 * window is the first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE ctl_id, worker_id, sleeper_id, holder_id, cyclic_id, never_id;
static SEMAPHORE_ID_TYPE sem;
static int worker_runs, sleeper_after, holder_after;
static RETURN_CODE_TYPE holder_rc = UNTOUCHED;

static void try_suspend(const char *check, PROCESS_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    SUSPEND(id, &rc);
    check_rc(check, expect, rc);
}

static void resume(PROCESS_ID_TYPE id)
{
    RETURN_CODE_TYPE rc;
    RESUME(id, &rc);
    setup_rc("RESUME", rc);
}

static void worker(void) { worker_runs++; }
static void never_body(void) {}

static void sleeper(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(3 * MS, &rc);
    sleeper_after = 1;
    trail_add("sleeper");
}

static void holder(void)
{
    WAIT_SEMAPHORE(sem, INFINITE_TIME_VALUE, &holder_rc);
    holder_after = 1;
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
    /* 0 ms: sleeper waits until 3 ms, holder on the semaphore, cyclic for its next period. */
    RETURN_CODE_TYPE rc;
    try_suspend("normal.self", ctl_id, INVALID_PARAM);
    try_suspend("normal.id_unknown", never_id + 1, INVALID_PARAM);
    try_suspend("normal.dormant", never_id, INVALID_MODE);
    try_suspend("normal.periodic", cyclic_id, INVALID_MODE);

    try_suspend("normal.ready", worker_id, NO_ERROR);
    check_str("normal.ready.state", "WAITING", process_state_name(worker_id));
    try_suspend("normal.already", worker_id, NO_ACTION);

    try_suspend("normal.timed_wait", sleeper_id, NO_ERROR);
    try_suspend("normal.semaphore", holder_id, NO_ERROR);
    SIGNAL_SEMAPHORE(sem, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
    SEMAPHORE_STATUS_TYPE st;
    GET_SEMAPHORE_STATUS(sem, &st, &rc);
    setup_rc("GET_SEMAPHORE_STATUS", rc);
    /* The semaphore went to the suspended waiter, which stays suspended. */
    check_int("normal.semaphore.given", 0, st.CURRENT_VALUE);
    check_int("normal.semaphore.no_waiter", 0, st.WAITING_PROCESSES);
    check_str("normal.semaphore.state", "WAITING", process_state_name(holder_id));

    TIMED_WAIT(5 * MS, &rc); /* 5 ms: the worker (priority 5) could have run */
    check_int("normal.ready.did_not_run", 0, worker_runs);
    /* Its delay ended at 3 ms, yet it still waits for RESUME. */
    check_int("normal.timed_wait.did_not_run", 0, sleeper_after);
    check_str("normal.timed_wait.state", "WAITING", process_state_name(sleeper_id));
    check_int("normal.semaphore.did_not_run", 0, holder_after);

    resume(sleeper_id); /* priority 20 over 10: it runs at once */
    trail_add("ctl");
    check_str("normal.resumed.runs_at_once", "sleeper,ctl", trail);
    resume(holder_id);
    check_int("normal.semaphore.resumed", 1, holder_after);
    check_rc("normal.semaphore.rc", NO_ERROR, holder_rc);
    resume(worker_id);
    TIMED_WAIT(1 * MS, &rc);
    check_int("normal.ready.resumed_ran", 1, worker_runs);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE("SEM", 0, 1, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE", rc);
    ctl_id = new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    worker_id = new_process("worker", worker, 5, INFINITE_TIME_VALUE);
    sleeper_id = new_process("sleeper", sleeper, 20, INFINITE_TIME_VALUE);
    holder_id = new_process("holder", holder, 25, INFINITE_TIME_VALUE);
    cyclic_id = new_process("cyclic", cyclic, 30, 20 * MS);
    never_id = new_process("never", never_body, 1, INFINITE_TIME_VALUE);

    try_suspend("init.id_zero", 0, INVALID_PARAM);
    try_suspend("init.id_negative", -1, INVALID_PARAM);
    try_suspend("init.dormant", never_id, INVALID_MODE);

    PROCESS_ID_TYPE started[] = {ctl_id, worker_id, sleeper_id, holder_id, cyclic_id};
    for (size_t i = 0; i < sizeof started / sizeof started[0]; i++) {
        START(started[i], &rc);
        setup_rc("START", rc);
    }
    enter_normal();
    return 1;
}
