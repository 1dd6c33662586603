/* SPDX-License-Identifier: Apache-2.0 */
/* APEX time management: TIMED_WAIT, PERIODIC_WAIT, GET_TIME, REPLENISH (ARINC 653 Part 1,
 * 3.4.2). */
#include "apex__rt.h"

void TIMED_WAIT(
    /*in */ SYSTEM_TIME_TYPE DELAY_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex_proc_t *p = rt->current;
    if (!apex__may_block()) {
        *RETURN_CODE = INVALID_MODE; /* the initialisation process, the error handler */
        return;
    }
    int64_t wake;
    if (DELAY_TIME < 0 || !apex__time_add(apex__now(), DELAY_TIME, &wake)) {
        *RETURN_CODE = INVALID_PARAM; /* includes INFINITE_TIME_VALUE */
        return;
    }
    *RETURN_CODE = NO_ERROR;
    if (DELAY_TIME == 0) {
        /* Round robin: to the back of the ready processes of the same priority. */
        apex__make_ready(p);
        swapcontext(&p->ctx, &rt->sched_ctx);
        return;
    }
    p->wait = WAIT_DELAY;
    p->wake_at = wake;
    apex__block(p);
}

void PERIODIC_WAIT(
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex_proc_t *p = apex__rt.current;
    if (!apex__may_block() || p->attr.PERIOD == INFINITE_TIME_VALUE) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    p->wait = WAIT_PERIOD;
    p->wake_at = p->next_release;
    *RETURN_CODE = NO_ERROR;
    apex__block(p);
}

void GET_TIME(
    /*out*/ SYSTEM_TIME_TYPE *SYSTEM_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_out(SYSTEM_TIME, sizeof *SYSTEM_TIME);
    *SYSTEM_TIME = apex__now();
    *RETURN_CODE = NO_ERROR;
}

void REPLENISH(
    /*in */ SYSTEM_TIME_TYPE BUDGET_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex_proc_t *p = rt->current;
    /* Nothing to replenish for the initialisation process, the error handler, or a process
     * with no time capacity (no deadline). */
    if (!p || p == &rt->eh || rt->mode != NORMAL || p->attr.TIME_CAPACITY == INFINITE_TIME_VALUE) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (BUDGET_TIME < INFINITE_TIME_VALUE) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    int64_t deadline = INFINITE_TIME_VALUE;
    bool in_range = BUDGET_TIME == INFINITE_TIME_VALUE ||
                    apex__time_add(apex__now(), BUDGET_TIME, &deadline);
    if (p->attr.PERIOD != INFINITE_TIME_VALUE &&
        (deadline == INFINITE_TIME_VALUE || !in_range || deadline > p->next_release)) {
        *RETURN_CODE = INVALID_MODE; /* a periodic process's deadline stays before its next release */
        return;
    }
    if (!in_range) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    p->deadline_time = deadline; /* now + BUDGET_TIME, or none for INFINITE_TIME_VALUE */
    p->deadline_missed = false;
    *RETURN_CODE = NO_ERROR;
}
