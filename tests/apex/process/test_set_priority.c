/* SPDX-License-Identifier: Apache-2.0 */
/* SET_PRIORITY (ARINC 653 Part 1, 3.3.2): the current priority changes at once; a ready
 * process raised above the caller preempts it; the process becomes the newest of its new
 * priority (FIFO within a priority), so a caller lowering itself runs after the ready
 * processes of its new priority and above; a priority-ordered queue follows current
 * priorities. The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE ctl_id, a_id, b_id, d_id, e_id, w1_id, w2_id, never_id;
static SEMAPHORE_ID_TYPE sem;

static void try_set(const char *check, PROCESS_ID_TYPE id, PRIORITY_TYPE prio,
                    RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    SET_PRIORITY(id, prio, &rc);
    check_rc(check, expect, rc);
}

static PROCESS_STATUS_TYPE status_of(PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    return st;
}

static void a(void) { trail_add("a"); }
static void b(void) { trail_add("b"); }
static void d(void) { trail_add("d"); }
static void e(void) { trail_add("e"); }
static void never_body(void) {}

static void waiter(const char *name)
{
    RETURN_CODE_TYPE rc;
    WAIT_SEMAPHORE(sem, INFINITE_TIME_VALUE, &rc);
    setup_rc("WAIT_SEMAPHORE", rc);
    trail_add("%s", name);
}

static void w1(void) { waiter("w1"); }
static void w2(void) { waiter("w2"); }

static void ctl(void)
{
    /* 0 ms: w1 (12) and w2 (11) wait on the semaphore; a, b, d (5) and e (4) are ready. */
    RETURN_CODE_TYPE rc;
    try_set("normal.priority_zero", ctl_id, 0, INVALID_PARAM);
    try_set("normal.priority_240", ctl_id, MAX_PRIORITY_VALUE + 1, INVALID_PARAM);
    try_set("normal.id_unknown", never_id + 1, 10, INVALID_PARAM);
    try_set("normal.dormant", never_id, 10, INVALID_MODE);

    try_set("normal.raise_ready", a_id, 20, NO_ERROR);
    trail_add("ctl");
    check_str("normal.raise_ready.preempts", "a,ctl", trail);
    try_set("normal.stopped", a_id, 7, INVALID_MODE);

    /* b, ready before d, becomes the newest of priority 5. */
    try_set("normal.same_priority", b_id, 5, NO_ERROR);
    trail_reset();
    try_set("normal.lower_self", ctl_id, 4, NO_ERROR);
    trail_add("ctl");
    check_str("normal.lower_self.order", "d,b,e,ctl", trail);
    PROCESS_STATUS_TYPE st = status_of(ctl_id);
    check_int("normal.current_priority", 4, st.CURRENT_PRIORITY);
    check_int("normal.base_priority", 10, st.ATTRIBUTES.BASE_PRIORITY);

    /* The semaphore serves by priority: w2 raised above w1 is served first. */
    try_set("normal.waiting", w2_id, 13, NO_ERROR);
    check_int("normal.waiting.current_priority", 13, status_of(w2_id).CURRENT_PRIORITY);
    trail_reset();
    SIGNAL_SEMAPHORE(sem, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
    SIGNAL_SEMAPHORE(sem, &rc);
    setup_rc("SIGNAL_SEMAPHORE", rc);
    trail_add("ctl");
    check_str("normal.waiting.queue_order", "w2,w1,ctl", trail);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE("SEM", 0, 2, PRIORITY, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE", rc);
    ctl_id = new_process("ctl", ctl, 10, INFINITE_TIME_VALUE);
    w1_id = new_process("w1", w1, 12, INFINITE_TIME_VALUE);
    w2_id = new_process("w2", w2, 11, INFINITE_TIME_VALUE);
    a_id = new_process("a", a, 5, INFINITE_TIME_VALUE);
    b_id = new_process("b", b, 5, INFINITE_TIME_VALUE);
    d_id = new_process("d", d, 5, INFINITE_TIME_VALUE);
    e_id = new_process("e", e, 4, INFINITE_TIME_VALUE);
    never_id = new_process("never", never_body, 1, INFINITE_TIME_VALUE);

    try_set("init.id_zero", 0, 10, INVALID_PARAM);
    try_set("init.priority_zero", ctl_id, 0, INVALID_PARAM);
    try_set("init.dormant", never_id, 10, INVALID_MODE);
    PROCESS_ID_TYPE started[] = {ctl_id, w1_id, w2_id, a_id, b_id, d_id, e_id};
    for (size_t i = 0; i < sizeof started / sizeof started[0]; i++) {
        START(started[i], &rc);
        setup_rc("START", rc);
    }
    /* STARTed, waiting for NORMAL mode: not DORMANT. */
    try_set("init.started", w1_id, 12, NO_ERROR);
    enter_normal();
    return 1;
}
