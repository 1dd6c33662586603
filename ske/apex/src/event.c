/* SPDX-License-Identifier: Apache-2.0 */
/* APEX event services: CREATE_EVENT, SET_EVENT, RESET_EVENT, WAIT_EVENT, GET_EVENT_ID,
 * GET_EVENT_STATUS (ARINC 653 Part 1, 3.7.2.4). SET_EVENT releases every waiting process,
 * in the order they started waiting; the event stays UP until RESET_EVENT. */
#include <string.h>

#include "apex__intra.h"

static int event_index(EVENT_ID_TYPE id)
{
    return id >= 1 && id <= apex__intra.n_events ? id - 1 : -1;
}

void CREATE_EVENT(
    /*in */ const char *EVENT_NAME,
    /*out*/ EVENT_ID_TYPE *EVENT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_intra_t *in = &apex__intra;
    apex__enter(RETURN_CODE);
    apex__check_name(EVENT_NAME);
    apex__check_out(EVENT_ID, sizeof *EVENT_ID);
    if (in->n_events >= MAX_NUMBER_OF_EVENTS) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (!apex__name_valid(EVENT_NAME)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__find_named(in->events, sizeof in->events[0], in->n_events, EVENT_NAME) >= 0) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (apex__rt.mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    apex_event_t *e = &in->events[in->n_events];
    memset(e, 0, sizeof *e);
    apex__name_copy(e->name, EVENT_NAME);
    e->state = DOWN;
    in->n_events++;
    *EVENT_ID = in->n_events;
    *RETURN_CODE = NO_ERROR;
}

void SET_EVENT(
    /*in */ EVENT_ID_TYPE EVENT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = event_index(EVENT_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__intra.events[k].state = UP;
    bool woke = false;
    apex_proc_t *w;
    while ((w = apex__waiter_next(WAIT_EVT, k, FIFO))) {
        apex__wait_done(w, NO_ERROR);
        woke = true;
    }
    *RETURN_CODE = NO_ERROR;
    if (woke)
        apex__preempt_check();
}

void RESET_EVENT(
    /*in */ EVENT_ID_TYPE EVENT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = event_index(EVENT_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__intra.events[k].state = DOWN;
    *RETURN_CODE = NO_ERROR;
}

void WAIT_EVENT(
    /*in */ EVENT_ID_TYPE EVENT_ID,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = event_index(EVENT_ID);
    int64_t until;
    if (k < 0 || !apex__time_out(TIME_OUT, &until)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__intra.events[k].state == UP) {
        *RETURN_CODE = NO_ERROR;
        return;
    }
    if (TIME_OUT == 0) {
        *RETURN_CODE = NOT_AVAILABLE;
        return;
    }
    if (!apex__may_block()) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    *RETURN_CODE = apex__wait_on(WAIT_EVT, k, until);
}

void GET_EVENT_ID(
    /*in */ const char *EVENT_NAME,
    /*out*/ EVENT_ID_TYPE *EVENT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(EVENT_NAME);
    apex__check_out(EVENT_ID, sizeof *EVENT_ID);
    int k = apex__find_named(apex__intra.events, sizeof apex__intra.events[0],
                             apex__intra.n_events, EVENT_NAME);
    if (k < 0) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    *EVENT_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void GET_EVENT_STATUS(
    /*in */ EVENT_ID_TYPE EVENT_ID,
    /*out*/ EVENT_STATUS_TYPE *EVENT_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = event_index(EVENT_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_out(EVENT_STATUS, sizeof *EVENT_STATUS);
    EVENT_STATUS->EVENT_STATE = apex__intra.events[k].state;
    EVENT_STATUS->WAITING_PROCESSES = apex__waiter_count(WAIT_EVT, k);
    *RETURN_CODE = NO_ERROR;
}
