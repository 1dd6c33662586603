/* SPDX-License-Identifier: Apache-2.0 */
/* SIGNAL_SEMAPHORE (ARINC 653 Part 1, 3.7.2.3): with no process waiting the value grows up
 * to its maximum; with processes waiting the first of them gets the unit (the value stays
 * 0) and, of higher priority than the caller, runs at once. The partition period is 20 ms;
 * its window is the first 10 ms of it. */
#include "apex_check.h"

static SEMAPHORE_ID_TYPE sem, zero_max, waited;

static void try_signal(const char *check, SEMAPHORE_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    SIGNAL_SEMAPHORE(id, &rc);
    check_rc(check, expect, rc);
}

static SEMAPHORE_STATUS_TYPE status_of(SEMAPHORE_ID_TYPE id)
{
    SEMAPHORE_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_SEMAPHORE_STATUS(id, &st, &rc);
    setup_rc("GET_SEMAPHORE_STATUS", rc);
    return st;
}

static void waiter(const char *name)
{
    RETURN_CODE_TYPE rc;
    WAIT_SEMAPHORE(waited, INFINITE_TIME_VALUE, &rc);
    setup_rc("WAIT_SEMAPHORE", rc);
    trail_add("%s", name);
}

static void hi(void) { waiter("hi"); }
static void lo(void) { waiter("lo"); }

static void ctl(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(1 * MS, &rc); /* hi (20) and lo (5) wait on WAITED, in that order */
    check_int("normal.waiting", 2, status_of(waited).WAITING_PROCESSES);
    try_signal("normal.to_higher", waited, NO_ERROR);
    trail_add("ctl");
    try_signal("normal.to_lower", waited, NO_ERROR);
    trail_add("ctl2");
    SEMAPHORE_STATUS_TYPE st = status_of(waited);
    check_int("normal.to_waiting.value", 0, st.CURRENT_VALUE);
    check_int("normal.to_waiting.waiting", 0, st.WAITING_PROCESSES);
    TIMED_WAIT(1 * MS, &rc);
    check_str("normal.order", "hi,ctl,ctl2,lo", trail);
    try_signal("normal.no_waiter", waited, NO_ERROR);
    check_int("normal.no_waiter.value", 1, status_of(waited).CURRENT_VALUE);
    try_signal("normal.id_unknown", waited + 1, INVALID_PARAM);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE("SEM", 0, 2, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE SEM", rc);
    CREATE_SEMAPHORE("ZERO_MAX", 0, 0, FIFO, &zero_max, &rc);
    setup_rc("CREATE_SEMAPHORE ZERO_MAX", rc);
    CREATE_SEMAPHORE("WAITED", 0, 3, FIFO, &waited, &rc);
    setup_rc("CREATE_SEMAPHORE WAITED", rc);

    try_signal("init.id_zero", 0, INVALID_PARAM);
    try_signal("init.id_negative", -1, INVALID_PARAM);
    try_signal("init.id_unknown", waited + 1, INVALID_PARAM);
    try_signal("init.first", sem, NO_ERROR);
    check_int("init.first.value", 1, status_of(sem).CURRENT_VALUE);
    try_signal("init.second", sem, NO_ERROR);
    check_int("init.second.value", 2, status_of(sem).CURRENT_VALUE);
    try_signal("init.at_maximum", sem, NO_ACTION);
    check_int("init.at_maximum.value", 2, status_of(sem).CURRENT_VALUE);
    try_signal("init.maximum_zero", zero_max, NO_ACTION);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("hi", hi, 20, INFINITE_TIME_VALUE);
    start_new_process("lo", lo, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
