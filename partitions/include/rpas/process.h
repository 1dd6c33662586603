/* SPDX-License-Identifier: Apache-2.0 */
/* A process of an RPAS partition created and started as the system model declares it (its
 * rpas_process_spec_t from the generated contract). */
#ifndef RPAS_PROCESS_H
#define RPAS_PROCESS_H

#include <stdio.h>

#include "ARINC653.h"
#include "rpas_system.h"

/* CREATE_PROCESS with the declared period as its time capacity, then START, or DELAYED_START
 * by its offset; *rc is the first error, and the caller reports it with the spec's name. */
static inline void rpas_start_process(const rpas_process_spec_t *s, void (*entry)(void),
                                      PROCESS_ID_TYPE *pid, RETURN_CODE_TYPE *rc)
{
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = s->period_ns,
        .TIME_CAPACITY = s->period_ns,
        .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)entry,
        .STACK_SIZE = s->stack_size,
        .BASE_PRIORITY = s->priority,
        .DEADLINE = s->deadline,
    };
    snprintf(a.NAME, sizeof a.NAME, "%s", s->name);
    CREATE_PROCESS(&a, pid, rc);
    if (*rc != NO_ERROR)
        return;
    if (s->offset_ns)
        DELAYED_START(*pid, s->offset_ns, rc);
    else
        START(*pid, rc);
}

#endif
