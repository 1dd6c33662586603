/* SPDX-License-Identifier: Apache-2.0 */
/* What the intra-partition communication services share (ARINC 653 Part 1, 3.7): object
 * names, message storage, time-outs and the waiting queues of buffers, blackboards,
 * semaphores and events. */
#include <stdlib.h>
#include <string.h>

#include "apex__intra.h"

apex_intra_t apex__intra;

bool apex__name_valid(const char *name)
{
    return name && strnlen(name, MAX_NAME_LENGTH) > 0;
}

bool apex__name_equal(const char *a, const char *b)
{
    size_t la = strnlen(a, MAX_NAME_LENGTH), lb = strnlen(b, MAX_NAME_LENGTH);
    return la == lb && memcmp(a, b, la) == 0;
}

int apex__find_named(const void *objects, size_t stride, int n, const char *name)
{
    for (int i = 0; name && i < n; i++)
        if (apex__name_equal((const char *)objects + (size_t)i * stride, name))
            return i;
    return -1;
}

void apex__name_copy(NAME_TYPE dst, const char *src)
{
    memset(dst, 0, sizeof(NAME_TYPE));
    memcpy(dst, src, strnlen(src, MAX_NAME_LENGTH));
}

void apex__copy_message(void *dst, const void *src, size_t n)
{
    apex__user_copy(true);
    memmove(dst, src, n);
    apex__user_copy(false);
}

void *apex__intra_alloc(size_t n)
{
    apex_intra_t *in = &apex__intra;
    /* Counted in whole 16-byte units, as the allocator hands them out. */
    size_t rounded = (n + 15u) & ~(size_t)15u;
    if (rounded < n || rounded > APEX_INTRA_STORAGE_MAX - in->storage_used)
        return NULL;
    void *m = calloc(1, rounded);
    if (m)
        in->storage_used += rounded;
    return m;
}

bool apex__time_out(SYSTEM_TIME_TYPE time_out, int64_t *until)
{
    *until = INT64_MAX;
    if (time_out < INFINITE_TIME_VALUE)
        return false;
    return time_out <= 0 || apex__time_add(apex__now(), time_out, until);
}

static bool waits_on(const apex_proc_t *p, apex_wait_t kind, int obj)
{
    return p->state == WAITING && p->wait == kind && p->wait_obj == obj;
}

apex_proc_t *apex__waiter_next(apex_wait_t kind, int obj, QUEUING_DISCIPLINE_TYPE discipline)
{
    apex_rt_t *rt = &apex__rt;
    bool prio = discipline == PRIORITY;
    apex_proc_t *best = NULL;
    for (int i = 0; i < rt->n_procs; i++) {
        apex_proc_t *p = &rt->procs[i];
        if (!waits_on(p, kind, obj))
            continue;
        if (!best || (prio && p->cur_prio > best->cur_prio) ||
            ((!prio || p->cur_prio == best->cur_prio) && p->wait_order < best->wait_order))
            best = p;
    }
    return best;
}

int apex__waiter_count(apex_wait_t kind, int obj)
{
    int n = 0;
    for (int i = 0; i < apex__rt.n_procs; i++)
        n += waits_on(&apex__rt.procs[i], kind, obj);
    return n;
}

RETURN_CODE_TYPE apex__wait_on(apex_wait_t kind, int obj, int64_t until)
{
    apex_proc_t *p = apex__rt.current;
    p->wait = kind;
    p->wait_obj = obj;
    p->wait_order = ++apex__rt.order;
    p->wake_at = until;
    return apex__block(p);
}

void apex__wait_done(apex_proc_t *p, RETURN_CODE_TYPE rc)
{
    p->wait_rc = rc;
    p->wake_at = INT64_MAX;
    apex__make_ready(p);
}
