/* SPDX-License-Identifier: Apache-2.0 */
/* APEX blackboard services: CREATE_BLACKBOARD, DISPLAY_BLACKBOARD, READ_BLACKBOARD,
 * CLEAR_BLACKBOARD, GET_BLACKBOARD_ID, GET_BLACKBOARD_STATUS (ARINC 653 Part 1, 3.7.2.2).
 * A blackboard holds the last message displayed until it is replaced or cleared; a display
 * hands the message to every process waiting to read, in the order they started waiting. */
#include <string.h>

#include "apex__intra.h"

static int blackboard_index(BLACKBOARD_ID_TYPE id)
{
    return id >= 1 && id <= apex__intra.n_blackboards ? id - 1 : -1;
}

void CREATE_BLACKBOARD(
    /*in */ const char *BLACKBOARD_NAME,
    /*in */ MESSAGE_SIZE_TYPE MAX_MESSAGE_SIZE,
    /*out*/ BLACKBOARD_ID_TYPE *BLACKBOARD_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_intra_t *in = &apex__intra;
    apex__enter(RETURN_CODE);
    apex__check_name(BLACKBOARD_NAME);
    apex__check_out(BLACKBOARD_ID, sizeof *BLACKBOARD_ID);
    if (in->n_blackboards >= MAX_NUMBER_OF_BLACKBOARDS) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (!apex__name_valid(BLACKBOARD_NAME)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__find_named(in->blackboards, sizeof in->blackboards[0], in->n_blackboards, BLACKBOARD_NAME) >= 0) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (MAX_MESSAGE_SIZE <= 0 || MAX_MESSAGE_SIZE > SYSTEM_LIMIT_MESSAGE_SIZE) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__rt.mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    APEX_BYTE *mem = apex__intra_alloc((size_t)MAX_MESSAGE_SIZE);
    if (!mem) {
        *RETURN_CODE = INVALID_CONFIG; /* insufficient storage */
        return;
    }
    apex_blackboard_t *bb = &in->blackboards[in->n_blackboards];
    memset(bb, 0, sizeof *bb);
    apex__name_copy(bb->name, BLACKBOARD_NAME);
    bb->max_size = MAX_MESSAGE_SIZE;
    bb->empty = EMPTY;
    bb->data = mem;
    in->n_blackboards++;
    *BLACKBOARD_ID = in->n_blackboards;
    *RETURN_CODE = NO_ERROR;
}

void DISPLAY_BLACKBOARD(
    /*in */ BLACKBOARD_ID_TYPE BLACKBOARD_ID,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ MESSAGE_SIZE_TYPE LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = blackboard_index(BLACKBOARD_ID);
    if (k < 0 || LENGTH > apex__intra.blackboards[k].max_size || LENGTH <= 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_addr(MESSAGE_ADDR);
    apex_blackboard_t *bb = &apex__intra.blackboards[k];
    apex__copy_message(bb->data, MESSAGE_ADDR, (size_t)LENGTH);
    bb->len = LENGTH;
    bb->empty = OCCUPIED;
    /* Every reader gets this message, even if the blackboard changes before it runs. */
    bool woke = false;
    apex_proc_t *r;
    while ((r = apex__waiter_next(WAIT_BB_READ, k, FIFO))) {
        apex__copy_message(r->q_buf, bb->data, (size_t)LENGTH);
        *r->q_len_out = LENGTH;
        apex__wait_done(r, NO_ERROR);
        woke = true;
    }
    *RETURN_CODE = NO_ERROR;
    if (woke)
        apex__preempt_check();
}

void READ_BLACKBOARD(
    /*in */ BLACKBOARD_ID_TYPE BLACKBOARD_ID,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*out*/ MESSAGE_SIZE_TYPE *LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = blackboard_index(BLACKBOARD_ID);
    int64_t until;
    if (k < 0 || !apex__time_out(TIME_OUT, &until)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_addr(MESSAGE_ADDR);
    apex__check_out(LENGTH, sizeof *LENGTH);
    const apex_blackboard_t *bb = &apex__intra.blackboards[k];
    if (bb->empty == OCCUPIED) {
        apex__copy_message(MESSAGE_ADDR, bb->data, (size_t)bb->len);
        *LENGTH = bb->len;
        *RETURN_CODE = NO_ERROR;
        return;
    }
    /* No message from here on: LENGTH 0, as for a queuing port. */
    if (TIME_OUT == 0) {
        *LENGTH = 0;
        *RETURN_CODE = NOT_AVAILABLE;
        return;
    }
    if (!apex__may_block()) {
        *LENGTH = 0;
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    /* DISPLAY_BLACKBOARD copies the message into MESSAGE_ADDR when it wakes this process. */
    apex_proc_t *p = apex__rt.current;
    MESSAGE_SIZE_TYPE len = 0;
    p->q_buf = MESSAGE_ADDR;
    p->q_len_out = &len;
    RETURN_CODE_TYPE rc = apex__wait_on(WAIT_BB_READ, k, until);
    *LENGTH = rc == NO_ERROR ? len : 0; /* 0: TIMED_OUT */
    *RETURN_CODE = rc;
}

void CLEAR_BLACKBOARD(
    /*in */ BLACKBOARD_ID_TYPE BLACKBOARD_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = blackboard_index(BLACKBOARD_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__intra.blackboards[k].empty = EMPTY;
    *RETURN_CODE = NO_ERROR;
}

void GET_BLACKBOARD_ID(
    /*in */ const char *BLACKBOARD_NAME,
    /*out*/ BLACKBOARD_ID_TYPE *BLACKBOARD_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(BLACKBOARD_NAME);
    apex__check_out(BLACKBOARD_ID, sizeof *BLACKBOARD_ID);
    int k = apex__find_named(apex__intra.blackboards, sizeof apex__intra.blackboards[0],
                             apex__intra.n_blackboards, BLACKBOARD_NAME);
    if (k < 0) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    *BLACKBOARD_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void GET_BLACKBOARD_STATUS(
    /*in */ BLACKBOARD_ID_TYPE BLACKBOARD_ID,
    /*out*/ BLACKBOARD_STATUS_TYPE *BLACKBOARD_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = blackboard_index(BLACKBOARD_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_out(BLACKBOARD_STATUS, sizeof *BLACKBOARD_STATUS);
    const apex_blackboard_t *bb = &apex__intra.blackboards[k];
    BLACKBOARD_STATUS->EMPTY_INDICATOR = bb->empty;
    BLACKBOARD_STATUS->MAX_MESSAGE_SIZE = bb->max_size;
    BLACKBOARD_STATUS->WAITING_PROCESSES = apex__waiter_count(WAIT_BB_READ, k);
    *RETURN_CODE = NO_ERROR;
}
