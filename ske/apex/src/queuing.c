/* SPDX-License-Identifier: Apache-2.0 */
/* APEX queuing port services (ARINC 653 Part 1, 3.6.2.2), CLEAR_QUEUING_PORT included. The
 * source port's queue is emptied by the SKE into the destination's at the end of the
 * source's window; a full destination queue loses the message and reports the overflow at
 * the next receive. */
#include <string.h>

#include "apex__rt.h"

static ske_queue_hdr_t *qhdr(int k) { return apex__rt.ports[k].mem; }

/* The consumer index: the SKE's for a source queue, ours for a destination queue. */
static uint32_t qtail(int k)
{
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    return d->dir == SKE_DIR_SOURCE ? atomic_load(&qhdr(k)->tail) : atomic_load(&d->rx_tail);
}

uint32_t apex__queue_count(int k)
{
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    uint32_t n = ske_queue_count(qhdr(k), d->max_nb, qtail(k));
    return n == UINT32_MAX ? d->max_nb : n;
}

int apex__queue_waiters(int k)
{
    int n = 0;
    for (int i = 0; i < apex__rt.n_procs; i++) {
        const apex_proc_t *p = &apex__rt.procs[i];
        if (p->state == WAITING && (p->wait == WAIT_QRECV || p->wait == WAIT_QSEND) && p->wait_port == k)
            n++;
    }
    return n;
}

/* Takes the oldest message of destination port k. */
static RETURN_CODE_TYPE receive_now(int k, APEX_BYTE *buf, MESSAGE_SIZE_TYPE *len)
{
    ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    uint32_t tail = atomic_load(&d->rx_tail);
    uint32_t l;
    int64_t t;
    apex__user_copy(true);
    ske_queue_peek(qhdr(k), d->max_size, d->max_nb, tail, buf, &l, &t);
    apex__user_copy(false);
    atomic_store(&d->rx_tail, tail + 1);
    *len = (MESSAGE_SIZE_TYPE)l;
    uint32_t ovf = atomic_load(&qhdr(k)->overflows);
    if (ovf != atomic_load(&d->overflow_ack)) {
        /* The queue overflowed since the last receive: the standard returns the message
         * with INVALID_CONFIG (Part 1, 3.6.2.2.3). */
        atomic_store(&d->overflow_ack, ovf);
        return INVALID_CONFIG;
    }
    return NO_ERROR;
}

static bool send_now(int k, const APEX_BYTE *msg, MESSAGE_SIZE_TYPE len)
{
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    apex__user_copy(true);
    bool ok = ske_queue_push(qhdr(k), d->max_size, d->max_nb, atomic_load(&qhdr(k)->tail), msg,
                             (uint32_t)len, apex__now());
    apex__user_copy(false);
    return ok;
}

/* The waiter to serve next: FIFO or priority order, as the port's discipline says. */
static apex_proc_t *next_waiter(int k)
{
    apex_proc_t *best = NULL;
    bool prio = apex__rt.ports[k].discipline == PRIORITY;
    for (int i = 0; i < apex__rt.n_procs; i++) {
        apex_proc_t *p = &apex__rt.procs[i];
        if (p->state != WAITING || (p->wait != WAIT_QRECV && p->wait != WAIT_QSEND) || p->wait_port != k)
            continue;
        if (!best || (prio && p->cur_prio > best->cur_prio) ||
            ((!prio || p->cur_prio == best->cur_prio) && p->wait_order < best->wait_order))
            best = p;
    }
    return best;
}

void apex__service_port_waiters(void)
{
    const ske_ctl_t *c = apex__rt.ctl;
    for (uint32_t k = 0; k < c->n_ports; k++) {
        if (c->ports[k].kind != SKE_PORT_QUEUING || !apex__rt.ports[k].created)
            continue;
        for (;;) {
            apex_proc_t *p = next_waiter((int)k);
            if (!p)
                break;
            if (p->wait == WAIT_QRECV) {
                if (apex__queue_count((int)k) == 0)
                    break;
                const ske_port_desc_t *d = &c->ports[k];
                int64_t arrived = ske_queue_head_time(qhdr((int)k), d->max_size, d->max_nb,
                                                      atomic_load(&d->rx_tail));
                if (arrived > p->wake_at)
                    break; /* its time-out came first: it times out (release_due) */
                p->wait_rc = receive_now((int)k, p->q_buf, p->q_len_out);
            } else {
                if (!send_now((int)k, p->q_msg, p->q_len))
                    break;
                p->wait_rc = NO_ERROR;
            }
            p->wake_at = INT64_MAX;
            apex__make_ready(p);
        }
    }
}

void CREATE_QUEUING_PORT(
    /*in */ const char *QUEUING_PORT_NAME,
    /*in */ MESSAGE_SIZE_TYPE MAX_MESSAGE_SIZE,
    /*in */ MESSAGE_RANGE_TYPE MAX_NB_MESSAGE,
    /*in */ PORT_DIRECTION_TYPE PORT_DIRECTION,
    /*in */ QUEUING_DISCIPLINE_TYPE QUEUING_DISCIPLINE,
    /*out*/ QUEUING_PORT_ID_TYPE *QUEUING_PORT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(QUEUING_PORT_NAME);
    apex__check_out(QUEUING_PORT_ID, sizeof *QUEUING_PORT_ID);
    int k = apex__port_by_name(QUEUING_PORT_NAME, SKE_PORT_QUEUING);
    if (k < 0) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    if (apex__rt.ports[k].created) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (MAX_MESSAGE_SIZE <= 0 || (uint32_t)MAX_MESSAGE_SIZE != d->max_size || MAX_NB_MESSAGE <= 0 ||
        (uint32_t)MAX_NB_MESSAGE != d->max_nb ||
        (PORT_DIRECTION != SOURCE && PORT_DIRECTION != DESTINATION) ||
        (uint32_t)PORT_DIRECTION != d->dir) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (QUEUING_DISCIPLINE != FIFO && QUEUING_DISCIPLINE != PRIORITY) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__rt.mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (!apex__port_map(k)) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    apex__rt.ports[k].discipline = QUEUING_DISCIPLINE;
    *QUEUING_PORT_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void SEND_QUEUING_MESSAGE(
    /*in */ QUEUING_PORT_ID_TYPE QUEUING_PORT_ID,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ MESSAGE_SIZE_TYPE LENGTH,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = apex__port_index(QUEUING_PORT_ID, SKE_PORT_QUEUING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    if (LENGTH > (MESSAGE_SIZE_TYPE)d->max_size) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    int64_t until = INT64_MAX;
    if (LENGTH <= 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_addr(MESSAGE_ADDR);
    if (TIME_OUT < INFINITE_TIME_VALUE ||
        (TIME_OUT > 0 && !apex__time_add(apex__now(), TIME_OUT, &until))) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (d->dir != SKE_DIR_SOURCE) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    /* Processes already waiting to send keep their turn. */
    if (apex__queue_waiters(k) == 0 && send_now(k, MESSAGE_ADDR, LENGTH)) {
        *RETURN_CODE = NO_ERROR;
        return;
    }
    if (TIME_OUT == 0) {
        *RETURN_CODE = NOT_AVAILABLE;
        return;
    }
    apex_proc_t *p = apex__rt.current;
    if (!apex__may_block()) {
        *RETURN_CODE = INVALID_MODE; /* the initialisation process, the error handler */
        return;
    }
    p->wait = WAIT_QSEND;
    p->wait_port = k;
    p->wait_order = ++apex__rt.order;
    p->q_msg = MESSAGE_ADDR;
    p->q_len = LENGTH;
    p->wake_at = until;
    *RETURN_CODE = apex__block(p);
}

void RECEIVE_QUEUING_MESSAGE(
    /*in */ QUEUING_PORT_ID_TYPE QUEUING_PORT_ID,
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*out*/ MESSAGE_SIZE_TYPE *LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_addr(MESSAGE_ADDR);
    apex__check_out(LENGTH, sizeof *LENGTH);
    int k = apex__port_index(QUEUING_PORT_ID, SKE_PORT_QUEUING);
    int64_t until = INT64_MAX;
    if (k < 0 || TIME_OUT < INFINITE_TIME_VALUE ||
        (TIME_OUT > 0 && !apex__time_add(apex__now(), TIME_OUT, &until))) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    if (d->dir != SKE_DIR_DESTINATION) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (apex__queue_count(k) > 0) {
        MESSAGE_SIZE_TYPE len;
        RETURN_CODE_TYPE rc = receive_now(k, MESSAGE_ADDR, &len);
        *LENGTH = len;
        *RETURN_CODE = rc;
        return;
    }
    /* From here on no message is received: LENGTH 0, as the standard's pseudo-code sets it
     * for an empty queue, a wait refused and a time-out. */
    if (TIME_OUT == 0) {
        *LENGTH = 0;
        *RETURN_CODE = NOT_AVAILABLE;
        return;
    }
    apex_proc_t *p = apex__rt.current;
    if (!apex__may_block()) {
        *LENGTH = 0;
        *RETURN_CODE = INVALID_MODE; /* the initialisation process, the error handler */
        return;
    }
    MESSAGE_SIZE_TYPE len = 0;
    p->wait = WAIT_QRECV;
    p->wait_port = k;
    p->wait_order = ++apex__rt.order;
    p->q_buf = MESSAGE_ADDR;
    p->q_len_out = &len;
    p->wake_at = until;
    RETURN_CODE_TYPE rc = apex__block(p);
    *LENGTH = rc == NO_ERROR || rc == INVALID_CONFIG ? len : 0; /* 0: TIMED_OUT */
    *RETURN_CODE = rc;
}

void GET_QUEUING_PORT_ID(
    /*in */ const char *QUEUING_PORT_NAME,
    /*out*/ QUEUING_PORT_ID_TYPE *QUEUING_PORT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(QUEUING_PORT_NAME);
    apex__check_out(QUEUING_PORT_ID, sizeof *QUEUING_PORT_ID);
    int k = apex__port_by_name(QUEUING_PORT_NAME, SKE_PORT_QUEUING);
    if (k < 0 || !apex__rt.ports[k].created) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    *QUEUING_PORT_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void GET_QUEUING_PORT_STATUS(
    /*in */ QUEUING_PORT_ID_TYPE QUEUING_PORT_ID,
    /*out*/ QUEUING_PORT_STATUS_TYPE *QUEUING_PORT_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_out(QUEUING_PORT_STATUS, sizeof *QUEUING_PORT_STATUS);
    int k = apex__port_index(QUEUING_PORT_ID, SKE_PORT_QUEUING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    QUEUING_PORT_STATUS->NB_MESSAGE = (MESSAGE_RANGE_TYPE)apex__queue_count(k);
    QUEUING_PORT_STATUS->MAX_NB_MESSAGE = (MESSAGE_RANGE_TYPE)d->max_nb;
    QUEUING_PORT_STATUS->MAX_MESSAGE_SIZE = (MESSAGE_SIZE_TYPE)d->max_size;
    QUEUING_PORT_STATUS->PORT_DIRECTION = (PORT_DIRECTION_TYPE)d->dir;
    QUEUING_PORT_STATUS->WAITING_PROCESSES = apex__queue_waiters(k);
    *RETURN_CODE = NO_ERROR;
}

void CLEAR_QUEUING_PORT(
    /*in */ QUEUING_PORT_ID_TYPE QUEUING_PORT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = apex__port_index(QUEUING_PORT_ID, SKE_PORT_QUEUING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    if (d->dir != SKE_DIR_DESTINATION) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    /* Everything that has arrived is consumed at once; an overflow before the clear concerned
     * messages now discarded, so the next receive does not report it. */
    atomic_store(&d->rx_tail, atomic_load(&qhdr(k)->head));
    atomic_store(&d->overflow_ack, atomic_load(&qhdr(k)->overflows));
    *RETURN_CODE = NO_ERROR;
}
