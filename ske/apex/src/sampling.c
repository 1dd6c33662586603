/* SPDX-License-Identifier: Apache-2.0 */
/* APEX sampling port services (ARINC 653 Part 1, 3.6.2.1), and the reading of a destination
 * port's latest message that the Part 2 extensions (sampling_ext.c) share. */
#include "apex__rt.h"

VALIDITY_TYPE apex__sampling_validity(int k, int64_t stamp)
{
    /* Valid when the message's age is within the refresh period (Part 1, 2.3.5.3); a stamp
     * from the future is a corrupted one: never valid. */
    int64_t age = apex__now() - stamp;
    return age >= 0 && age <= apex__rt.ctl->ports[k].refresh_ns ? VALID : INVALID;
}

bool apex__sampling_take(int k, APEX_BYTE *buf, MESSAGE_SIZE_TYPE *len, int64_t *stamp)
{
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    apex_port_t *ap = &apex__rt.ports[k];
    uint32_t n, seq;
    apex__user_copy(true);
    bool got = ske_sampling_read_seq(ap->mem, d->max_size, buf, &n, stamp, &seq);
    apex__user_copy(false);
    if (!got)
        return false;
    VALIDITY_TYPE v = apex__sampling_validity(k, *stamp);
    if (!ap->validity_known || ap->last_validity != v)
        apex__event(SKE_EV_PORT_VALIDITY, k, v, NULL, 0);
    ap->validity_known = true;
    ap->last_validity = v;
    ap->read_seq = seq;
    *len = (MESSAGE_SIZE_TYPE)n;
    return true;
}

void CREATE_SAMPLING_PORT(
    /*in */ const char *SAMPLING_PORT_NAME,
    /*in */ MESSAGE_SIZE_TYPE MAX_MESSAGE_SIZE,
    /*in */ PORT_DIRECTION_TYPE PORT_DIRECTION,
    /*in */ SYSTEM_TIME_TYPE REFRESH_PERIOD,
    /*out*/ SAMPLING_PORT_ID_TYPE *SAMPLING_PORT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(SAMPLING_PORT_NAME);
    apex__check_out(SAMPLING_PORT_ID, sizeof *SAMPLING_PORT_ID);
    int k = apex__port_by_name(SAMPLING_PORT_NAME, SKE_PORT_SAMPLING);
    if (k < 0) {
        *RETURN_CODE = INVALID_CONFIG; /* no such port in the configuration */
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    if (apex__rt.ports[k].created) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (MAX_MESSAGE_SIZE <= 0 || (uint32_t)MAX_MESSAGE_SIZE != d->max_size ||
        (PORT_DIRECTION != SOURCE && PORT_DIRECTION != DESTINATION) ||
        (uint32_t)PORT_DIRECTION != d->dir || REFRESH_PERIOD < 0 ||
        REFRESH_PERIOD != d->refresh_ns) {
        *RETURN_CODE = INVALID_CONFIG;
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
    *SAMPLING_PORT_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void WRITE_SAMPLING_MESSAGE(
    /*in */ SAMPLING_PORT_ID_TYPE SAMPLING_PORT_ID,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ MESSAGE_SIZE_TYPE LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    int k = apex__port_index(SAMPLING_PORT_ID, SKE_PORT_SAMPLING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    if (LENGTH > (MESSAGE_SIZE_TYPE)d->max_size) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (LENGTH <= 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_addr(MESSAGE_ADDR);
    if (d->dir != SKE_DIR_SOURCE) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (__builtin_expect(apex__rt.ports[k].out_fault != APEX_OUT_NORMAL, 0) &&
        apex__fault_write(k, MESSAGE_ADDR, LENGTH)) {
        *RETURN_CODE = NO_ERROR; /* as far as the writer can tell */
        return;
    }
    apex__user_copy(true);
    ske_sampling_write(apex__rt.ports[k].mem, d->max_size, MESSAGE_ADDR, (uint32_t)LENGTH, apex__now());
    apex__user_copy(false);
    *RETURN_CODE = NO_ERROR;
}

void READ_SAMPLING_MESSAGE(
    /*in */ SAMPLING_PORT_ID_TYPE SAMPLING_PORT_ID,
    /*out*/ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*out*/ MESSAGE_SIZE_TYPE *LENGTH,
    /*out*/ VALIDITY_TYPE *VALIDITY,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_addr(MESSAGE_ADDR);
    apex__check_out(LENGTH, sizeof *LENGTH);
    apex__check_out(VALIDITY, sizeof *VALIDITY);
    int k = apex__port_index(SAMPLING_PORT_ID, SKE_PORT_SAMPLING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (apex__rt.ctl->ports[k].dir != SKE_DIR_DESTINATION) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    MESSAGE_SIZE_TYPE len;
    int64_t stamp;
    if (!apex__sampling_take(k, MESSAGE_ADDR, &len, &stamp)) {
        /* No message was ever written: the standard's empty port. */
        *LENGTH = 0;
        *VALIDITY = INVALID;
        *RETURN_CODE = NO_ACTION;
        return;
    }
    *LENGTH = len;
    *VALIDITY = apex__rt.ports[k].last_validity;
    *RETURN_CODE = NO_ERROR;
}

void GET_SAMPLING_PORT_ID(
    /*in */ const char *SAMPLING_PORT_NAME,
    /*out*/ SAMPLING_PORT_ID_TYPE *SAMPLING_PORT_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_name(SAMPLING_PORT_NAME);
    apex__check_out(SAMPLING_PORT_ID, sizeof *SAMPLING_PORT_ID);
    int k = apex__port_by_name(SAMPLING_PORT_NAME, SKE_PORT_SAMPLING);
    if (k < 0 || !apex__rt.ports[k].created) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    *SAMPLING_PORT_ID = k + 1;
    *RETURN_CODE = NO_ERROR;
}

void GET_SAMPLING_PORT_STATUS(
    /*in */ SAMPLING_PORT_ID_TYPE SAMPLING_PORT_ID,
    /*out*/ SAMPLING_PORT_STATUS_TYPE *SAMPLING_PORT_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_out(SAMPLING_PORT_STATUS, sizeof *SAMPLING_PORT_STATUS);
    int k = apex__port_index(SAMPLING_PORT_ID, SKE_PORT_SAMPLING);
    if (k < 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const ske_port_desc_t *d = &apex__rt.ctl->ports[k];
    SAMPLING_PORT_STATUS->REFRESH_PERIOD = d->refresh_ns;
    SAMPLING_PORT_STATUS->MAX_MESSAGE_SIZE = (MESSAGE_SIZE_TYPE)d->max_size;
    SAMPLING_PORT_STATUS->PORT_DIRECTION = (PORT_DIRECTION_TYPE)d->dir;
    SAMPLING_PORT_STATUS->LAST_MSG_VALIDITY = apex__rt.ports[k].last_validity;
    *RETURN_CODE = NO_ERROR;
}
