/* SPDX-License-Identifier: Apache-2.0 */
/* APEX sampling port extensions (ARINC 653 Part 2): READ_UPDATED_SAMPLING_MESSAGE,
 * GET_SAMPLING_PORT_CURRENT_STATUS, READ_SAMPLING_MESSAGE_CONDITIONAL. A message counts as
 * read once any read service of this port has delivered it; what is delivered is always the
 * channel's latest message. */
#include "apex__rt.h"

/* Destination port k of a read service, or -1 with the return code set. */
static int destination(SAMPLING_PORT_ID_TYPE id, RETURN_CODE_TYPE *rc)
{
    int k = apex__port_index(id, SKE_PORT_SAMPLING);
    if (k < 0) {
        *rc = INVALID_PARAM;
        return -1;
    }
    if (apex__rt.ctl->ports[k].dir != SKE_DIR_DESTINATION) {
        *rc = INVALID_MODE;
        return -1;
    }
    return k;
}

/* The latest message of port k: false when none was ever written. */
static bool latest(int k, uint32_t *seq, int64_t *stamp)
{
    return ske_sampling_latest(apex__rt.ports[k].mem, apex__rt.ctl->ports[k].max_size, seq, stamp);
}

void READ_UPDATED_SAMPLING_MESSAGE(
    /*in */ SAMPLING_PORT_ID_TYPE SAMPLING_PORT_ID,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*out*/ MESSAGE_SIZE_TYPE *LENGTH,
    /*out*/ UPDATED_TYPE *UPDATED,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_addr(MESSAGE_ADDR);
    apex__check_out(LENGTH, sizeof *LENGTH);
    apex__check_out(UPDATED, sizeof *UPDATED);
    int k = destination(SAMPLING_PORT_ID, RETURN_CODE);
    if (k < 0)
        return;
    uint32_t seq;
    int64_t stamp;
    bool full = latest(k, &seq, &stamp);
    if (!full || seq == apex__rt.ports[k].read_seq) {
        /* Nothing new: the buffer is left alone, LENGTH says no message was read. */
        *LENGTH = 0;
        *UPDATED = full ? CONSUMED_MESSAGE : EMPTY_PORT;
        *RETURN_CODE = NO_ACTION;
        return;
    }
    MESSAGE_SIZE_TYPE len;
    apex__sampling_take(k, MESSAGE_ADDR, &len, &stamp);
    *LENGTH = len;
    *UPDATED = NEW_MESSAGE;
    *RETURN_CODE = NO_ERROR;
}

void GET_SAMPLING_PORT_CURRENT_STATUS(
    /*in */ SAMPLING_PORT_ID_TYPE SAMPLING_PORT_ID,
    /*out*/ SAMPLING_PORT_CURRENT_STATUS_TYPE *SAMPLING_PORT_CURRENT_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_out(SAMPLING_PORT_CURRENT_STATUS, sizeof *SAMPLING_PORT_CURRENT_STATUS);
    int k = apex__port_index(SAMPLING_PORT_ID, SKE_PORT_SAMPLING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    uint32_t seq = 0;
    int64_t stamp = 0;
    bool full = latest(k, &seq, &stamp);
    SAMPLING_PORT_CURRENT_STATUS_TYPE *st = SAMPLING_PORT_CURRENT_STATUS;
    st->REFRESH_PERIOD = d->refresh_ns;
    st->TIME_STAMP = full ? stamp : 0;
    st->MAX_MESSAGE_SIZE = (MESSAGE_SIZE_TYPE)d->max_size;
    st->PORT_DIRECTION = (PORT_DIRECTION_TYPE)d->dir;
    st->MESSAGE_AGE = full && apex__sampling_validity(k, stamp) == VALID ? FRESH : STALE;
    /* A source port never reads: after its first write it always holds a new message. */
    st->UPDATED = !full ? EMPTY_PORT
                : seq == apex__rt.ports[k].read_seq ? CONSUMED_MESSAGE
                                                    : NEW_MESSAGE;
    *RETURN_CODE = NO_ERROR;
}

void READ_SAMPLING_MESSAGE_CONDITIONAL(
    /*in */ SAMPLING_PORT_ID_TYPE SAMPLING_PORT_ID,
    /*in */ SYSTEM_TIME_TYPE REF_TIME_STAMP,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*out*/ MESSAGE_SIZE_TYPE *LENGTH,
    /*out*/ SYSTEM_TIME_TYPE *TIME_STAMP,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_addr(MESSAGE_ADDR);
    apex__check_out(LENGTH, sizeof *LENGTH);
    apex__check_out(TIME_STAMP, sizeof *TIME_STAMP);
    int k = destination(SAMPLING_PORT_ID, RETURN_CODE);
    if (k < 0)
        return;
    if (REF_TIME_STAMP < 0) {
        *RETURN_CODE = INVALID_PARAM; /* no time stamp is negative (INFINITE_TIME_VALUE included) */
        return;
    }
    uint32_t seq;
    int64_t stamp;
    if (!latest(k, &seq, &stamp)) {
        *LENGTH = 0;
        *TIME_STAMP = 0; /* as AIR does: no message, no time stamp */
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (stamp <= REF_TIME_STAMP) {
        /* Not newer than the reference: the caller learns the stamp of what is there. */
        *LENGTH = 0;
        *TIME_STAMP = stamp;
        *RETURN_CODE = NO_ACTION;
        return;
    }
    MESSAGE_SIZE_TYPE len;
    apex__sampling_take(k, MESSAGE_ADDR, &len, &stamp);
    *LENGTH = len;
    *TIME_STAMP = stamp;
    *RETURN_CODE = NO_ERROR;
}
