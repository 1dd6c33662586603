/* SPDX-License-Identifier: Apache-2.0 */
/* APEX process management: CREATE_PROCESS, START, STOP_SELF, GET_MY_ID, GET_PROCESS_ID,
 * GET_PROCESS_STATUS (ARINC 653 Part 1, 3.3.2). Processes are user-level contexts that the
 * partition's own scheduler runs one at a time. */
#include <string.h>
#include <sys/mman.h>

#include "apex__rt.h"

#define STACK_MIN (64u * 1024u) /* Linux C library calls need more than embedded stacks */
#define STACK_MAX (64u * 1024u * 1024u)
#define GUARD_SIZE 4096u

static size_t name_len(const char *n) { return strnlen(n, MAX_NAME_LENGTH); }

static bool same_name(const char *a, const char *b)
{
    size_t la = name_len(a), lb = name_len(b);
    return la == lb && memcmp(a, b, la) == 0;
}

static apex_proc_t *proc_by_id(PROCESS_ID_TYPE id)
{
    if (id < 1 || id > apex__rt.n_procs)
        return NULL;
    return &apex__rt.procs[id - 1];
}

static void proc_event(apex_proc_t *p, int what)
{
    apex__event(SKE_EV_PROCESS, p->id, what, p->attr.NAME, (uint32_t)name_len(p->attr.NAME));
}

/* Entry of every process context: run the entry point; returning from it stops the process. */
static void trampoline(void)
{
    apex_proc_t *p = apex__rt.current;
    ((void (*)(void))p->attr.ENTRY_POINT)();
    STOP_SELF();
}

void CREATE_PROCESS(
    /*in */ PROCESS_ATTRIBUTE_TYPE *ATTRIBUTES,
    /*out*/ PROCESS_ID_TYPE *PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__sync();
    if (!ATTRIBUTES) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    const PROCESS_ATTRIBUTE_TYPE *a = ATTRIBUTES;
    if (rt->n_procs >= MAX_NUMBER_OF_PROCESSES) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    for (int i = 0; i < rt->n_procs; i++)
        if (same_name(rt->procs[i].attr.NAME, a->NAME)) {
            *RETURN_CODE = NO_ACTION;
            return;
        }
    if (a->STACK_SIZE == 0 || a->STACK_SIZE > STACK_MAX || !a->ENTRY_POINT || name_len(a->NAME) == 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (a->BASE_PRIORITY < MIN_PRIORITY_VALUE || a->BASE_PRIORITY > MAX_PRIORITY_VALUE) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (a->PERIOD != INFINITE_TIME_VALUE && a->PERIOD <= 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    int64_t part_period = rt->ctl->period_ns;
    if (a->PERIOD != INFINITE_TIME_VALUE && part_period > 0 && a->PERIOD % part_period != 0) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    if (a->TIME_CAPACITY != INFINITE_TIME_VALUE && a->TIME_CAPACITY <= 0) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (a->PERIOD != INFINITE_TIME_VALUE &&
        (a->TIME_CAPACITY == INFINITE_TIME_VALUE || a->TIME_CAPACITY > a->PERIOD)) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (a->DEADLINE != SOFT && a->DEADLINE != HARD) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (rt->mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    size_t stack = a->STACK_SIZE < STACK_MIN ? STACK_MIN : a->STACK_SIZE;
    stack = (stack + 4095u) & ~(size_t)4095u;
    size_t map = stack + GUARD_SIZE;
    void *mem = mmap(NULL, map, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_STACK, -1, 0);
    if (mem == MAP_FAILED) {
        *RETURN_CODE = INVALID_CONFIG; /* insufficient storage */
        return;
    }
    mprotect(mem, GUARD_SIZE, PROT_NONE); /* stacks grow down onto the guard page */
    apex_proc_t *p = &rt->procs[rt->n_procs];
    memset(p, 0, sizeof *p);
    p->attr = *a;
    p->id = rt->n_procs + 1;
    p->state = DORMANT;
    p->cur_prio = a->BASE_PRIORITY;
    p->deadline_time = INFINITE_TIME_VALUE;
    p->wake_at = INT64_MAX;
    p->stack_map = mem;
    p->stack_map_size = map;
    rt->n_procs++;
    *PROCESS_ID = p->id;
    *RETURN_CODE = NO_ERROR;
}

void START(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__sync();
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (p->state != DORMANT || p->start_pending) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    int64_t now = apex__now();
    int64_t deadline = INFINITE_TIME_VALUE;
    if (rt->mode == NORMAL && p->attr.PERIOD == INFINITE_TIME_VALUE &&
        p->attr.TIME_CAPACITY != INFINITE_TIME_VALUE &&
        !apex__time_add(now, p->attr.TIME_CAPACITY, &deadline)) {
        *RETURN_CODE = INVALID_CONFIG; /* the deadline time is out of range */
        return;
    }
    getcontext(&p->ctx);
    p->ctx.uc_stack.ss_sp = (char *)p->stack_map + GUARD_SIZE;
    p->ctx.uc_stack.ss_size = p->stack_map_size - GUARD_SIZE;
    p->ctx.uc_link = NULL;
    makecontext(&p->ctx, trampoline, 0);
    p->cur_prio = p->attr.BASE_PRIORITY;
    p->wake_at = INT64_MAX;
    proc_event(p, SKE_PROC_EV_START);
    if (rt->mode != NORMAL) {
        /* Released when the partition enters NORMAL mode (ARINC 653 Part 1, 2.3.2). */
        p->start_pending = true;
        *RETURN_CODE = NO_ERROR;
        return;
    }
    if (p->attr.PERIOD == INFINITE_TIME_VALUE) {
        p->deadline_time = deadline;
        apex__make_ready(p);
    } else {
        p->state = WAITING;
        p->wait = WAIT_PERIOD;
        p->wake_at = apex__next_period_start(now);
    }
    *RETURN_CODE = NO_ERROR;
    apex__preempt_check();
}

void STOP_SELF(void)
{
    apex_rt_t *rt = &apex__rt;
    apex__sync();
    apex_proc_t *p = rt->current;
    if (!p)
        return; /* the initialisation process is not an ARINC process: nothing to stop */
    p->state = DORMANT;
    p->wait = WAIT_NONE;
    p->wake_at = INT64_MAX;
    p->deadline_time = INFINITE_TIME_VALUE;
    proc_event(p, SKE_PROC_EV_STOP);
    swapcontext(&p->ctx, &rt->sched_ctx);
    /* A dormant process is only resumed through START, which gives it a fresh context. */
}

void GET_MY_ID(
    /*out*/ PROCESS_ID_TYPE *PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__sync();
    if (!apex__rt.current) {
        *RETURN_CODE = INVALID_MODE; /* the initialisation process has no process ID */
        return;
    }
    *PROCESS_ID = apex__rt.current->id;
    *RETURN_CODE = NO_ERROR;
}

void GET_PROCESS_ID(
    /*in */ const char *PROCESS_NAME,
    /*out*/ PROCESS_ID_TYPE *PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__sync();
    for (int i = 0; i < apex__rt.n_procs; i++)
        if (same_name(apex__rt.procs[i].attr.NAME, PROCESS_NAME)) {
            *PROCESS_ID = apex__rt.procs[i].id;
            *RETURN_CODE = NO_ERROR;
            return;
        }
    *RETURN_CODE = INVALID_CONFIG;
}

void GET_PROCESS_STATUS(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*out*/ PROCESS_STATUS_TYPE *PROCESS_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__sync();
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    PROCESS_STATUS->ATTRIBUTES = p->attr;
    PROCESS_STATUS->CURRENT_PRIORITY = p->cur_prio;
    PROCESS_STATUS->DEADLINE_TIME = p->deadline_time;
    PROCESS_STATUS->PROCESS_STATE = p->start_pending ? WAITING : p->state;
    *RETURN_CODE = NO_ERROR;
}
