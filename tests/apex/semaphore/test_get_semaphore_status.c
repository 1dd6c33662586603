/* SPDX-License-Identifier: Apache-2.0 */
/* GET_SEMAPHORE_STATUS (ARINC 653 Part 1, 3.7.2.3): NO_ERROR with the current and maximum
 * values and the number of waiting processes; INVALID_PARAM for an unknown identifier (output
 * untouched). The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static SEMAPHORE_ID_TYPE sem, other;

static SEMAPHORE_STATUS_TYPE status_of(SEMAPHORE_ID_TYPE id)
{
    SEMAPHORE_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_SEMAPHORE_STATUS(id, &st, &rc);
    setup_rc("GET_SEMAPHORE_STATUS", rc);
    return st;
}

static void bad_id(const char *check, SEMAPHORE_ID_TYPE id)
{
    SEMAPHORE_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_SEMAPHORE_STATUS(id, &st, &rc);
    check_rc(check, INVALID_PARAM, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.untouched", check);
    check_int(n, UNTOUCHED, st.CURRENT_VALUE);
}

static void waiter(void)
{
    RETURN_CODE_TYPE rc;
    WAIT_SEMAPHORE(sem, INFINITE_TIME_VALUE, &rc);
}

static void ctl(void)
{
    /* 0 ms: three processes wait on SEM. */
    SEMAPHORE_STATUS_TYPE st = status_of(sem);
    check_int("normal.current_value", 0, st.CURRENT_VALUE);
    check_int("normal.waiting", 3, st.WAITING_PROCESSES);
    RETURN_CODE_TYPE rc;
    SIGNAL_SEMAPHORE(sem, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
    check_int("normal.signalled.waiting", 2, status_of(sem).WAITING_PROCESSES);
    bad_id("normal.id_unknown", other + 1);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE("SEM", 2, 4, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE SEM", rc);
    CREATE_SEMAPHORE("OTHER", 7, 9, PRIORITY, &other, &rc);
    setup_rc("CREATE_SEMAPHORE OTHER", rc);

    SEMAPHORE_STATUS_TYPE st = status_of(sem);
    check_int("init.current_value", 2, st.CURRENT_VALUE);
    check_int("init.maximum_value", 4, st.MAXIMUM_VALUE);
    check_int("init.waiting", 0, st.WAITING_PROCESSES);
    st = status_of(other);
    check_int("init.other.current_value", 7, st.CURRENT_VALUE);
    check_int("init.other.maximum_value", 9, st.MAXIMUM_VALUE);
    WAIT_SEMAPHORE(sem, 0, &rc);
    setup_rc("WAIT_SEMAPHORE", rc);
    WAIT_SEMAPHORE(sem, 0, &rc);
    setup_rc("WAIT_SEMAPHORE", rc);
    check_int("init.taken.current_value", 0, status_of(sem).CURRENT_VALUE);

    bad_id("init.id_zero", 0);
    bad_id("init.id_negative", -1);
    bad_id("init.id_unknown", other + 1);

    start_new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    start_new_process("waiter1", waiter, 20, INFINITE_TIME_VALUE);
    start_new_process("waiter2", waiter, 20, INFINITE_TIME_VALUE);
    start_new_process("waiter3", waiter, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
