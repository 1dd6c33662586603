/* SPDX-License-Identifier: Apache-2.0 */
/* APEX multiple module schedules (ARINC 653 Part 2, 3.2): SET_MODULE_SCHEDULE,
 * GET_MODULE_SCHEDULE_STATUS, GET_MODULE_SCHEDULE_ID. A switch takes effect at the start of
 * the next major frame; only partitions the module allows (ima:ScheduleChange) may ask. */
#include <string.h>

#include "apex__rt.h"

static int schedule_index(SCHEDULE_ID_TYPE id)
{
    const ske_ctl_t *c = apex__rt.ctl;
    for (uint32_t i = 0; i < c->n_schedules && i < SKE_SCHEDULES; i++)
        if (c->schedule_ids[i] == id)
            return (int)i;
    return -1;
}

void SET_MODULE_SCHEDULE(
    /*in */ SCHEDULE_ID_TYPE SCHEDULE_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    ske_ctl_t *c = apex__rt.ctl;
    apex__enter(RETURN_CODE);
    if (schedule_index(SCHEDULE_ID) < 0) {
        *RETURN_CODE = INVALID_PARAM; /* no such schedule */
        return;
    }
    if (!c->schedule_change_allowed) {
        *RETURN_CODE = INVALID_CONFIG; /* the partition may not change the module schedule */
        return;
    }
    atomic_store(&c->schedule_request, SCHEDULE_ID);
    atomic_fetch_add(&c->schedule_request_seq, 1);
    *RETURN_CODE = NO_ERROR;
}

void GET_MODULE_SCHEDULE_STATUS(
    /*out*/ SCHEDULE_STATUS_TYPE *SCHEDULE_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    const ske_ctl_t *c = apex__rt.ctl;
    apex__enter(RETURN_CODE);
    apex__check_out(SCHEDULE_STATUS, sizeof *SCHEDULE_STATUS);
    SCHEDULE_STATUS->TIME_OF_LAST_SCHEDULE_SWITCH = atomic_load(&c->last_switch_ns);
    SCHEDULE_STATUS->CURRENT_SCHEDULE = atomic_load(&c->current_schedule);
    /* A request of ours the SKE has not taken yet is the next schedule already. */
    bool pending = atomic_load(&c->schedule_request_seq) != atomic_load(&c->schedule_request_ack);
    SCHEDULE_STATUS->NEXT_SCHEDULE = pending ? atomic_load(&c->schedule_request)
                                             : atomic_load(&c->next_schedule);
    *RETURN_CODE = NO_ERROR;
}

void GET_MODULE_SCHEDULE_ID(
    /*in */ const char *SCHEDULE_NAME,
    /*out*/ SCHEDULE_ID_TYPE *SCHEDULE_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    const ske_ctl_t *c = apex__rt.ctl;
    apex__enter(RETURN_CODE);
    apex__check_name(SCHEDULE_NAME);
    apex__check_out(SCHEDULE_ID, sizeof *SCHEDULE_ID);
    size_t n = strnlen(SCHEDULE_NAME, MAX_NAME_LENGTH);
    for (uint32_t i = 0; i < c->n_schedules && i < SKE_SCHEDULES; i++)
        if (strnlen(c->schedule_names[i], SKE_NAME_MAX) == n &&
            memcmp(c->schedule_names[i], SCHEDULE_NAME, n) == 0) {
            *SCHEDULE_ID = c->schedule_ids[i];
            *RETURN_CODE = NO_ERROR;
            return;
        }
    *RETURN_CODE = INVALID_CONFIG; /* no schedule of that name */
}
