/* SPDX-License-Identifier: Apache-2.0 */
/* STOP (ARINC 653 Part 1, 3.3.2): another process becomes DORMANT wherever it was (ready,
 * waiting on a delay, a semaphore or its next period, suspended) and leaves every queue;
 * START restarts it from its entry point. The partition period is 20 ms; its window is the
 * first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE ctl_id, ready_id, delay_id, sem_id, cyclic_id, susp_id, never_id, pending_id;
static SEMAPHORE_ID_TYPE sem;
static int delay_woke, sem_got, cyclic_runs, susp_runs, pending_ran;

static void try_stop(const char *check, PROCESS_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    STOP(id, &rc);
    check_rc(check, expect, rc);
}

static void ready_body(void) { trail_add("ready"); }
static void never_body(void) {}
static void pending_body(void) { pending_ran = 1; }
static void susp_body(void) { susp_runs++; }

static void delay_body(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
    delay_woke = 1;
}

static void sem_body(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_SEMAPHORE(sem, INFINITE_TIME_VALUE, &rc);
    sem_got = 1;
}

static void cyclic(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        cyclic_runs++;
        PERIODIC_WAIT(&rc);
    }
}

static SEMAPHORE_STATUS_TYPE sem_status(void)
{
    SEMAPHORE_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_SEMAPHORE_STATUS(sem, &st, &rc);
    setup_rc("GET_SEMAPHORE_STATUS", rc);
    return st;
}

static void ctl(void)
{
    /* 0 ms: the semaphore waiter, the periodic process and the delayed one ran and wait. */
    RETURN_CODE_TYPE rc;
    try_stop("normal.self", ctl_id, INVALID_PARAM);

    try_stop("normal.ready", ready_id, NO_ERROR);
    check_str("normal.ready.state", "DORMANT", process_state_name(ready_id));
    try_stop("normal.dormant", ready_id, NO_ACTION);

    check_int("normal.semaphore.waiting_before", 1, sem_status().WAITING_PROCESSES);
    try_stop("normal.waiting_semaphore", sem_id, NO_ERROR);
    check_int("normal.semaphore.waiting_after", 0, sem_status().WAITING_PROCESSES);
    SIGNAL_SEMAPHORE(sem, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
    check_int("normal.semaphore.value_after_signal", 1, sem_status().CURRENT_VALUE);

    try_stop("normal.timed_wait", delay_id, NO_ERROR);
    check_str("normal.timed_wait.state", "DORMANT", process_state_name(delay_id));
    try_stop("normal.periodic_wait", cyclic_id, NO_ERROR);

    START(susp_id, &rc);
    setup_rc("START susp", rc);
    SUSPEND(susp_id, &rc);
    setup_rc("SUSPEND susp", rc);
    try_stop("normal.suspended", susp_id, NO_ERROR);
    START(susp_id, &rc);
    check_rc("normal.suspended.restart", NO_ERROR, rc);

    START(ready_id, &rc);
    check_rc("normal.restart", NO_ERROR, rc);

    TIMED_WAIT(8 * MS, &rc); /* the lower-priority processes run */
    check_int("normal.timed_wait.never_woke", 0, delay_woke);
    check_int("normal.semaphore.never_got", 0, sem_got);
    check_str("normal.restart.ran", "ready", trail);
    check_int("normal.suspended.restart.ran", 1, susp_runs);

    TIMED_WAIT(20 * MS, &rc); /* past the periodic process's next release point */
    check_int("normal.periodic_wait.no_release", 1, cyclic_runs);
    check_int("pending.never_ran", 0, pending_ran);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE("SEM", 0, 1, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE", rc);
    ctl_id = new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    ready_id = new_process("ready", ready_body, 5, INFINITE_TIME_VALUE);
    delay_id = new_process("delay", delay_body, 20, INFINITE_TIME_VALUE);
    sem_id = new_process("sem", sem_body, 30, INFINITE_TIME_VALUE);
    cyclic_id = new_process("cyclic", cyclic, 25, 20 * MS);
    susp_id = new_process("susp", susp_body, 3, INFINITE_TIME_VALUE);
    never_id = new_process("never", never_body, 1, INFINITE_TIME_VALUE);
    pending_id = new_process("pending", pending_body, 2, INFINITE_TIME_VALUE);

    try_stop("init.id_zero", 0, INVALID_PARAM);
    try_stop("init.id_negative", -1, INVALID_PARAM);
    try_stop("init.id_unknown", pending_id + 1, INVALID_PARAM);
    try_stop("init.dormant", never_id, NO_ACTION);
    /* STARTed during initialisation: stopped before NORMAL mode, it never runs. */
    START(pending_id, &rc);
    setup_rc("START pending", rc);
    try_stop("init.started", pending_id, NO_ERROR);
    check_str("init.started.state", "DORMANT", process_state_name(pending_id));

    PROCESS_ID_TYPE started[] = {ctl_id, ready_id, delay_id, sem_id, cyclic_id};
    for (size_t i = 0; i < sizeof started / sizeof started[0]; i++) {
        START(started[i], &rc);
        setup_rc("START", rc);
    }
    enter_normal();
    return 1;
}
