/* SPDX-License-Identifier: Apache-2.0 */
/* APEX semaphore services: CREATE_SEMAPHORE, WAIT_SEMAPHORE, SIGNAL_SEMAPHORE,
 * GET_SEMAPHORE_ID, GET_SEMAPHORE_STATUS (ARINC 653 Part 1, 3.7.2.3). A signal with processes
 * waiting passes the unit straight to the first of them (the value stays 0), in the queuing
 * discipline's order. */
#include <string.h>

#include "apex__intra.h"

static int semaphore_index(SEMAPHORE_ID_TYPE id)
{
    return id >= 1 && id <= apex__intra.n_semaphores ? id - 1 : -1;
}

void CREATE_SEMAPHORE(
    /*in */ const char *SEMAPHORE_NAME,
    /*in */ SEMAPHORE_VALUE_TYPE CURRENT_VALUE,
    /*in */ SEMAPHORE_VALUE_TYPE MAXIMUM_VALUE,
    /*in */ QUEUING_DISCIPLINE_TYPE QUEUING_DISCIPLINE,
    /*out*/ SEMAPHORE_ID_TYPE *SEMAPHORE_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_intra_t *in = &apex__intra;
    apex__enter(RETURN_CODE);
    apex__check_name(SEMAPHORE_NAME);
    apex__check_out(SEMAPHORE_ID, sizeof *SEMAPHORE_ID);
    if (in->n_semaphores >= MAX_NUMBER_OF_SEMAPHORES) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (!apex__name_valid(SEMAPHORE_NAME)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__find_named(in->semaphores, sizeof in->semaphores[0], in->n_semaphores, SEMAPHORE_NAME) >= 0) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (CURRENT_VALUE < 0 || CURRENT_VALUE > MAX_SEMAPHORE_VALUE || MAXIMUM_VALUE < 0 ||
        MAXIMUM_VALUE > MAX_SEMAPHORE_VALUE || CURRENT_VALUE > MAXIMUM_VALUE ||
        (QUEUING_DISCIPLINE != FIFO && QUEUING_DISCIPLINE != PRIORITY)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__rt.mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    apex_semaphore_t *s = &in->semaphores[in->n_semaphores];
    memset(s, 0, sizeof *s);
    apex__name_copy(s->name, SEMAPHORE_NAME);
    s->value = CURRENT_VALUE;
    s->max = MAXIMUM_VALUE;
    s->discipline = QUEUING_DISCIPLINE;
    in->n_semaphores++;
    *SEMAPHORE_ID = in->n_semaphores;
    *RETURN_CODE = NO_ERROR;
}

void WAIT_SEMAPHORE(
    /*in */ SEMAPHORE_ID_TYPE SEMAPHORE_ID,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = semaphore_index(SEMAPHORE_ID);
    int64_t until;
    if (k < 0 || !apex__time_out(TIME_OUT, &until)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex_semaphore_t *s = &apex__intra.semaphores[k];
    if (s->value > 0) {
        s->value--;
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
    *RETURN_CODE = apex__wait_on(WAIT_SEM, k, until);
}

void SIGNAL_SEMAPHORE(
    /*in */ SEMAPHORE_ID_TYPE SEMAPHORE_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = semaphore_index(SEMAPHORE_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex_semaphore_t *s = &apex__intra.semaphores[k];
    if (s->value == s->max) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    apex_proc_t *w = apex__waiter_next(WAIT_SEM, k, s->discipline);
    if (!w) {
        s->value++;
        *RETURN_CODE = NO_ERROR;
        return;
    }
    apex__wait_done(w, NO_ERROR);
    *RETURN_CODE = NO_ERROR;
    apex__preempt_check();
}

void GET_SEMAPHORE_ID(
    /*in */ const char *SEMAPHORE_NAME,
    /*out*/ SEMAPHORE_ID_TYPE *SEMAPHORE_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(SEMAPHORE_NAME);
    apex__check_out(SEMAPHORE_ID, sizeof *SEMAPHORE_ID);
    int k = apex__find_named(apex__intra.semaphores, sizeof apex__intra.semaphores[0],
                             apex__intra.n_semaphores, SEMAPHORE_NAME);
    if (k < 0) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    *SEMAPHORE_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void GET_SEMAPHORE_STATUS(
    /*in */ SEMAPHORE_ID_TYPE SEMAPHORE_ID,
    /*out*/ SEMAPHORE_STATUS_TYPE *SEMAPHORE_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = semaphore_index(SEMAPHORE_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_out(SEMAPHORE_STATUS, sizeof *SEMAPHORE_STATUS);
    const apex_semaphore_t *s = &apex__intra.semaphores[k];
    SEMAPHORE_STATUS->CURRENT_VALUE = s->value;
    SEMAPHORE_STATUS->MAXIMUM_VALUE = s->max;
    SEMAPHORE_STATUS->WAITING_PROCESSES = apex__waiter_count(WAIT_SEM, k);
    *RETURN_CODE = NO_ERROR;
}
