/* SPDX-License-Identifier: Apache-2.0 */
/* A port of an RPAS partition created as the system model declares it (its rpas_port_spec_t
 * from the generated contract): sampling or queuing, by the spec's kind. */
#ifndef RPAS_PORT_H
#define RPAS_PORT_H

#include "ARINC653.h"
#include "rpas_system.h"

/* CREATE_SAMPLING_PORT or CREATE_QUEUING_PORT (FIFO); *id gets the port's identifier. */
static inline void rpas_create_port(const rpas_port_spec_t *ps, long *id, RETURN_CODE_TYPE *rc)
{
    if (ps->kind == RPAS_PORT_QUEUING) {
        QUEUING_PORT_ID_TYPE q = 0;
        CREATE_QUEUING_PORT((char *)ps->name, ps->size, ps->max_nb_messages, ps->direction, FIFO,
                            &q, rc);
        *id = (long)q;
    } else {
        SAMPLING_PORT_ID_TYPE s = 0;
        CREATE_SAMPLING_PORT((char *)ps->name, ps->size, ps->direction, ps->refresh_ns, &s, rc);
        *id = (long)s;
    }
}

/* Every port of a partition's contract table (spec[0..n-1]) into ids[]: NULL, or the name of
 * the port that could not be created (*rc says why). */
static inline const char *rpas_create_ports(const rpas_port_spec_t *spec, int n, long ids[],
                                            RETURN_CODE_TYPE *rc)
{
    *rc = NO_ERROR;
    for (int p = 0; p < n; p++) {
        rpas_create_port(&spec[p], &ids[p], rc);
        if (*rc != NO_ERROR)
            return spec[p].name;
    }
    return NULL;
}

#endif
