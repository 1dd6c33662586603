/* SPDX-License-Identifier: Apache-2.0 */
/* APEX partition management: GET_PARTITION_STATUS, SET_PARTITION_MODE
 * (ARINC 653 Part 1, 3.2.2). */
#include "apex__rt.h"

void GET_PARTITION_STATUS(
    /*out*/ PARTITION_STATUS_TYPE *PARTITION_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_out(PARTITION_STATUS, sizeof *PARTITION_STATUS);
    const ske_ctl_t *c = apex__rt.ctl;
    PARTITION_STATUS->PERIOD = c->period_ns;
    PARTITION_STATUS->DURATION = c->duration_ns;
    PARTITION_STATUS->IDENTIFIER = c->partition_id;
    PARTITION_STATUS->LOCK_LEVEL = apex__rt.lock_level;
    PARTITION_STATUS->OPERATING_MODE = apex__rt.mode;
    PARTITION_STATUS->START_CONDITION = (START_CONDITION_TYPE)c->start_condition;
    PARTITION_STATUS->NUM_ASSIGNED_CORES = 1;
    *RETURN_CODE = NO_ERROR;
}

void SET_PARTITION_MODE(
    /*in */ OPERATING_MODE_TYPE OPERATING_MODE,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    if (OPERATING_MODE != IDLE && OPERATING_MODE != COLD_START && OPERATING_MODE != WARM_START &&
        OPERATING_MODE != NORMAL) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (OPERATING_MODE == NORMAL && rt->mode == NORMAL) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (OPERATING_MODE == WARM_START && rt->mode == COLD_START) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (OPERATING_MODE == NORMAL) {
        if (rt->current) {
            /* Only the initialisation process runs outside NORMAL mode. */
            *RETURN_CODE = INVALID_MODE;
            return;
        }
        *RETURN_CODE = NO_ERROR;
        apex__enter_normal(); /* the initialisation process ends here */
    }
    /* IDLE, COLD_START, WARM_START: the SKE shuts down or restarts the partition when it
     * gets the CPU back, which is now. */
    atomic_store(&rt->ctl->mode_request, (uint32_t)OPERATING_MODE);
    atomic_fetch_add(&rt->ctl->mode_request_seq, 1);
    for (;;)
        apex__yield_cpu();
}
