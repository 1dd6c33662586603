/* SPDX-License-Identifier: Apache-2.0 */
/* START (ARINC 653 Part 1, 3.3.2), from the initialisation process and from a process in
 * NORMAL mode. The partition period is 20 ms; its window is the first 10 ms of it. */
#include <stdint.h>

#include "apex_check.h"

static PROCESS_ID_TYPE worker_id, helper_id, cyclic_id, late_id, huge_id;
static int helper_runs;

static void try_start(const char *check, PROCESS_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    RETURN_CODE_TYPE rc;
    START(id, &rc);
    check_rc(check, expect, rc);
}

static const char *state_of(PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    return state_name(st.PROCESS_STATE);
}

static void helper(void) { helper_runs++; }

static void cyclic(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        PERIODIC_WAIT(&rc);
    }
}

static void late(void)
{
    /* Started at 1 ms: released at the partition's next period start. */
    check_int("normal.periodic.first_release", 20 * MS, now_ns());
}

static void huge(void) {}

static void worker(void)
{
    RETURN_CODE_TYPE rc;
    try_start("normal.self_running", worker_id, NO_ACTION);
    check_str("normal.ready.state", "READY", state_of(cyclic_id));
    try_start("normal.ready", cyclic_id, NO_ACTION);

    /* A higher-priority process started in NORMAL mode runs at once. */
    try_start("normal.dormant", helper_id, NO_ERROR);
    check_int("normal.dormant.preempts", 1, helper_runs);
    /* Once it has stopped it is dormant again and can be started again. */
    try_start("normal.dormant_again", helper_id, NO_ERROR);
    check_int("normal.dormant_again.preempts", 2, helper_runs);

    TIMED_WAIT(1 * MS, &rc); /* cyclic runs and waits for its next release */
    check_str("normal.waiting.state", "WAITING", state_of(cyclic_id));
    try_start("normal.waiting", cyclic_id, NO_ACTION);

    try_start("normal.id_zero", 0, INVALID_PARAM);
    try_start("normal.id_unknown", huge_id + 1, INVALID_PARAM);

    try_start("normal.periodic", late_id, NO_ERROR);

    /* DEADLINE_TIME = now + TIME_CAPACITY cannot be represented once now > 0. */
    TIMED_WAIT(20 * MS, &rc);
    try_start("normal.deadline_out_of_range", huge_id, INVALID_CONFIG);
}

int main(void)
{
    worker_id = new_process("worker", worker, 10, INFINITE_TIME_VALUE);
    helper_id = new_process("helper", helper, 20, INFINITE_TIME_VALUE);
    cyclic_id = new_process("cyclic", cyclic, 5, 20 * MS);
    late_id = new_process("late", late, 15, 20 * MS);
    PROCESS_ATTRIBUTE_TYPE a = process_attributes("huge", huge, 1, INFINITE_TIME_VALUE, INT64_MAX);
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &huge_id, &rc);
    setup_rc("CREATE_PROCESS huge", rc);

    try_start("init.id_zero", 0, INVALID_PARAM);
    try_start("init.id_negative", -1, INVALID_PARAM);
    try_start("init.id_unknown", huge_id + 1, INVALID_PARAM);
    try_start("init.dormant", worker_id, NO_ERROR);
    try_start("init.already_started", worker_id, NO_ACTION);
    try_start("init.periodic", cyclic_id, NO_ERROR);
    enter_normal();
    return 1;
}
