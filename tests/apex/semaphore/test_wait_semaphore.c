/* SPDX-License-Identifier: Apache-2.0 */
/* WAIT_SEMAPHORE (ARINC 653 Part 1, 3.7.2.3): every return code, from the initialisation
 * process and from processes; waiting processes served in FIFO or priority order. The
 * partition period is 20 ms; its window is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static SEMAPHORE_ID_TYPE sem, fifo, prio;
static PROCESS_ID_TYPE f_lo_id, f_hi_id, p_lo_id, p_hi_id;

static void try_wait(const char *check, SEMAPHORE_ID_TYPE id, SYSTEM_TIME_TYPE time_out,
                     RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    WAIT_SEMAPHORE(id, time_out, &rc);
    check_rc(check, expect, rc);
}

static SEMAPHORE_VALUE_TYPE value_of(SEMAPHORE_ID_TYPE id)
{
    SEMAPHORE_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_SEMAPHORE_STATUS(id, &st, &rc);
    setup_rc("GET_SEMAPHORE_STATUS", rc);
    return st.CURRENT_VALUE;
}

static void signal_sem(SEMAPHORE_ID_TYPE id)
{
    RETURN_CODE_TYPE rc;
    SIGNAL_SEMAPHORE(id, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
}

static void waiter(const char *name, SEMAPHORE_ID_TYPE id, bool later)
{
    RETURN_CODE_TYPE rc;
    if (later)
        TIMED_WAIT(1 * MS, &rc);
    WAIT_SEMAPHORE(id, INFINITE_TIME_VALUE, &rc);
    char n[32];
    snprintf(n, sizeof n, "%s.rc", name);
    check_rc(n, NO_ERROR, rc);
}

static void f_lo(void) { waiter("f_lo", fifo, false); }
static void f_hi(void) { waiter("f_hi", fifo, true); }
static void p_lo(void) { waiter("p_lo", prio, false); }
static void p_hi(void) { waiter("p_hi", prio, true); }

static void signaller(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
    signal_sem(sem);
}

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    /* 0 ms; SEM is 0. Meanwhile f_lo (priority 5, at 0 ms) then f_hi (6, at 1 ms) wait on
     * FIFO, p_lo (7, at 0 ms) then p_hi (8, at 1 ms) on PRIO. */
    try_wait("normal.zero.no_wait", sem, 0, NOT_AVAILABLE);
    SYSTEM_TIME_TYPE t0 = now_ns();
    try_wait("normal.zero.timed_out", sem, 2 * MS, TIMED_OUT);
    check_int("normal.zero.timed_out.elapsed", 2 * MS, now_ns() - t0);
    /* 2 ms + INT64_MAX is past the end of the clock. */
    try_wait("normal.timeout_beyond_clock", sem, INT64_MAX, INVALID_PARAM);

    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    try_wait("normal.preemption_locked", sem, 1 * MS, INVALID_MODE);
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);

    /* One signal each: FIFO releases the longest waiting, PRIORITY the highest priority. */
    signal_sem(fifo);
    check_str("normal.fifo.first", "READY", process_state_name(f_lo_id));
    check_str("normal.fifo.second", "WAITING", process_state_name(f_hi_id));
    signal_sem(prio);
    check_str("normal.priority.first", "READY", process_state_name(p_hi_id));
    check_str("normal.priority.second", "WAITING", process_state_name(p_lo_id));
    signal_sem(fifo);
    signal_sem(prio);

    /* The signaller (priority 4) signals SEM at 5 ms. */
    t0 = now_ns();
    try_wait("normal.zero.wait", sem, INFINITE_TIME_VALUE, NO_ERROR);
    check_int("normal.zero.wait.elapsed", 3 * MS, now_ns() - t0);
    check_int("normal.zero.wait.value", 0, value_of(sem));
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE("SEM", 2, 5, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE SEM", rc);
    CREATE_SEMAPHORE("FIFO", 0, 5, FIFO, &fifo, &rc);
    setup_rc("CREATE_SEMAPHORE FIFO", rc);
    CREATE_SEMAPHORE("PRIO", 0, 5, PRIORITY, &prio, &rc);
    setup_rc("CREATE_SEMAPHORE PRIO", rc);

    try_wait("init.id_zero", 0, 0, INVALID_PARAM);
    try_wait("init.id_unknown", prio + 1, 0, INVALID_PARAM);
    try_wait("init.timeout_minus_2", sem, -2, INVALID_PARAM);
    try_wait("init.available", sem, 0, NO_ERROR);
    check_int("init.available.value", 1, value_of(sem));
    try_wait("init.available.infinite", sem, INFINITE_TIME_VALUE, NO_ERROR);
    check_int("init.available.infinite.value", 0, value_of(sem));
    try_wait("init.zero.no_wait", sem, 0, NOT_AVAILABLE);
    /* The initialisation process cannot wait. */
    try_wait("init.zero.would_wait", sem, 1 * MS, INVALID_MODE);
    try_wait("init.zero.would_wait_forever", sem, INFINITE_TIME_VALUE, INVALID_MODE);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    f_lo_id = start_new_process("f_lo", f_lo, 5, INFINITE_TIME_VALUE);
    f_hi_id = start_new_process("f_hi", f_hi, 6, INFINITE_TIME_VALUE);
    p_lo_id = start_new_process("p_lo", p_lo, 7, INFINITE_TIME_VALUE);
    p_hi_id = start_new_process("p_hi", p_hi, 8, INFINITE_TIME_VALUE);
    start_new_process("signaller", signaller, 4, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
