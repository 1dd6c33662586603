/* SPDX-License-Identifier: Apache-2.0 */
/* APEX buffer services: CREATE_BUFFER, SEND_BUFFER, RECEIVE_BUFFER, GET_BUFFER_ID,
 * GET_BUFFER_STATUS (ARINC 653 Part 1, 3.7.2.1). A buffer is a bounded FIFO of messages
 * between the processes of one partition. A message sent while receivers wait goes straight
 * to the first of them, and a receive that makes room takes the first waiting sender's
 * message at once: senders wait only on a full buffer, receivers only on an empty one, and
 * each queue is served in its discipline's order. */
#include <string.h>

#include "apex__intra.h"

static int buffer_index(BUFFER_ID_TYPE id)
{
    return id >= 1 && id <= apex__intra.n_buffers ? id - 1 : -1;
}

static APEX_BYTE *slot(const apex_buffer_t *b, MESSAGE_RANGE_TYPE i)
{
    return b->data + (size_t)i * (size_t)b->max_size;
}

static void push(apex_buffer_t *b, const APEX_BYTE *msg, MESSAGE_SIZE_TYPE len)
{
    MESSAGE_RANGE_TYPE i = (b->head + b->count) % b->max_nb;
    apex__copy_message(slot(b, i), msg, (size_t)len);
    b->lens[i] = len;
    b->count++;
}

static MESSAGE_SIZE_TYPE pop(apex_buffer_t *b, APEX_BYTE *msg)
{
    MESSAGE_SIZE_TYPE len = b->lens[b->head];
    apex__copy_message(msg, slot(b, b->head), (size_t)len);
    b->head = (b->head + 1) % b->max_nb;
    b->count--;
    return len;
}

void CREATE_BUFFER(
    /*in */ const char *BUFFER_NAME,
    /*in */ MESSAGE_SIZE_TYPE MAX_MESSAGE_SIZE,
    /*in */ MESSAGE_RANGE_TYPE MAX_NB_MESSAGE,
    /*in */ QUEUING_DISCIPLINE_TYPE QUEUING_DISCIPLINE,
    /*out*/ BUFFER_ID_TYPE *BUFFER_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_intra_t *in = &apex__intra;
    apex__enter(RETURN_CODE);
    apex__check_name(BUFFER_NAME);
    apex__check_out(BUFFER_ID, sizeof *BUFFER_ID);
    if (in->n_buffers >= MAX_NUMBER_OF_BUFFERS) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (!apex__name_valid(BUFFER_NAME)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__find_named(in->buffers, sizeof in->buffers[0], in->n_buffers, BUFFER_NAME) >= 0) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (MAX_MESSAGE_SIZE <= 0 || MAX_MESSAGE_SIZE > SYSTEM_LIMIT_MESSAGE_SIZE ||
        MAX_NB_MESSAGE <= 0 || MAX_NB_MESSAGE > SYSTEM_LIMIT_NUMBER_OF_MESSAGES ||
        (QUEUING_DISCIPLINE != FIFO && QUEUING_DISCIPLINE != PRIORITY)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__rt.mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    /* At most 2^20 messages of 2^20 bytes: the product fits in 64 bits. */
    size_t n = (size_t)MAX_NB_MESSAGE;
    APEX_BYTE *mem =
        apex__intra_alloc(n * (size_t)MAX_MESSAGE_SIZE + n * sizeof(MESSAGE_SIZE_TYPE));
    if (!mem) {
        *RETURN_CODE = INVALID_CONFIG; /* insufficient storage */
        return;
    }
    apex_buffer_t *b = &in->buffers[in->n_buffers];
    memset(b, 0, sizeof *b);
    apex__name_copy(b->name, BUFFER_NAME);
    b->max_size = MAX_MESSAGE_SIZE;
    b->max_nb = MAX_NB_MESSAGE;
    b->discipline = QUEUING_DISCIPLINE;
    b->lens = (MESSAGE_SIZE_TYPE *)mem; /* the allocation is 16-byte aligned */
    b->data = mem + n * sizeof(MESSAGE_SIZE_TYPE);
    in->n_buffers++;
    *BUFFER_ID = in->n_buffers;
    *RETURN_CODE = NO_ERROR;
}

void SEND_BUFFER(
    /*in */ BUFFER_ID_TYPE BUFFER_ID,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ MESSAGE_SIZE_TYPE LENGTH,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = buffer_index(BUFFER_ID);
    int64_t until;
    if (k < 0 || LENGTH > apex__intra.buffers[k].max_size || LENGTH <= 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_addr(MESSAGE_ADDR);
    if (!apex__time_out(TIME_OUT, &until)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex_buffer_t *b = &apex__intra.buffers[k];
    if (b->count < b->max_nb) {
        apex_proc_t *r = apex__waiter_next(WAIT_BUF_RECV, k, b->discipline);
        if (!r) {
            push(b, MESSAGE_ADDR, LENGTH);
            *RETURN_CODE = NO_ERROR;
            return;
        }
        apex__copy_message(r->q_buf, MESSAGE_ADDR, (size_t)LENGTH);
        *r->q_len_out = LENGTH;
        apex__wait_done(r, NO_ERROR);
        *RETURN_CODE = NO_ERROR;
        apex__preempt_check();
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
    apex_proc_t *p = apex__rt.current;
    p->q_msg = MESSAGE_ADDR;
    p->q_len = LENGTH;
    *RETURN_CODE = apex__wait_on(WAIT_BUF_SEND, k, until);
}

void RECEIVE_BUFFER(
    /*in */ BUFFER_ID_TYPE BUFFER_ID,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*out*/ MESSAGE_SIZE_TYPE *LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = buffer_index(BUFFER_ID);
    int64_t until;
    if (k < 0 || !apex__time_out(TIME_OUT, &until)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_addr(MESSAGE_ADDR);
    apex__check_out(LENGTH, sizeof *LENGTH);
    apex_buffer_t *b = &apex__intra.buffers[k];
    if (b->count > 0) {
        MESSAGE_SIZE_TYPE len = pop(b, MESSAGE_ADDR);
        apex_proc_t *s = apex__waiter_next(WAIT_BUF_SEND, k, b->discipline);
        if (s) {
            push(b, s->q_msg, s->q_len);
            apex__wait_done(s, NO_ERROR);
        }
        *LENGTH = len;
        *RETURN_CODE = NO_ERROR;
        if (s)
            apex__preempt_check();
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
    /* A sender copies the message into MESSAGE_ADDR when it hands it over. */
    apex_proc_t *p = apex__rt.current;
    MESSAGE_SIZE_TYPE len = 0;
    p->q_buf = MESSAGE_ADDR;
    p->q_len_out = &len;
    RETURN_CODE_TYPE rc = apex__wait_on(WAIT_BUF_RECV, k, until);
    *LENGTH = rc == NO_ERROR ? len : 0; /* 0: TIMED_OUT */
    *RETURN_CODE = rc;
}

void GET_BUFFER_ID(
    /*in */ const char *BUFFER_NAME,
    /*out*/ BUFFER_ID_TYPE *BUFFER_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(BUFFER_NAME);
    apex__check_out(BUFFER_ID, sizeof *BUFFER_ID);
    int k = apex__find_named(apex__intra.buffers, sizeof apex__intra.buffers[0],
                             apex__intra.n_buffers, BUFFER_NAME);
    if (k < 0) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    *BUFFER_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void GET_BUFFER_STATUS(
    /*in */ BUFFER_ID_TYPE BUFFER_ID,
    /*out*/ BUFFER_STATUS_TYPE *BUFFER_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = buffer_index(BUFFER_ID);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_out(BUFFER_STATUS, sizeof *BUFFER_STATUS);
    const apex_buffer_t *b = &apex__intra.buffers[k];
    BUFFER_STATUS->NB_MESSAGE = b->count;
    BUFFER_STATUS->MAX_NB_MESSAGE = b->max_nb;
    BUFFER_STATUS->MAX_MESSAGE_SIZE = b->max_size;
    BUFFER_STATUS->WAITING_PROCESSES =
        apex__waiter_count(WAIT_BUF_SEND, k) + apex__waiter_count(WAIT_BUF_RECV, k);
    *RETURN_CODE = NO_ERROR;
}
