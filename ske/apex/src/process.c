/* SPDX-License-Identifier: Apache-2.0 */
/* APEX process management: CREATE_PROCESS, START, DELAYED_START, STOP_SELF, STOP,
 * SUSPEND_SELF, SUSPEND, RESUME, SET_PRIORITY, LOCK_PREEMPTION, UNLOCK_PREEMPTION, GET_MY_ID,
 * GET_PROCESS_ID, GET_PROCESS_STATUS (ARINC 653 Part 1, 3.3.2). Processes are user-level
 * contexts that the partition's own scheduler runs one at a time. */
#include <signal.h>
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

/* A new context at the entry point, for START and DELAYED_START. */
static void fresh_context(apex_proc_t *p)
{
    getcontext(&p->ctx);
    /* A fresh process runs with no signal blocked, even when STARTed by the error handler
     * while a fault signal is still blocked. */
    sigemptyset(&p->ctx.uc_sigmask);
    p->ctx.uc_stack.ss_sp = (char *)p->stack_map + GUARD_SIZE;
    p->ctx.uc_stack.ss_size = p->stack_map_size - GUARD_SIZE;
    p->ctx.uc_link = NULL;
    makecontext(&p->ctx, trampoline, 0);
    p->cur_prio = p->attr.BASE_PRIORITY;
    p->wake_at = INT64_MAX;
    p->deadline_missed = false;
    p->suspended = false;
    p->start_delay = 0;
}

/* STOP_SELF and STOP: out of every queue, no deadline, no preemption lock (ARINC 653 Part 1,
 * 3.3.2: stopping the process that locked preemption unlocks it). */
static void make_dormant(apex_proc_t *p)
{
    apex_rt_t *rt = &apex__rt;
    p->state = DORMANT;
    p->wait = WAIT_NONE;
    p->wake_at = INT64_MAX;
    p->deadline_time = INFINITE_TIME_VALUE;
    p->start_pending = false;
    p->start_delay = 0;
    p->suspended = false;
    if (rt->lock_owner == p) {
        rt->lock_level = 0;
        rt->lock_owner = NULL;
    }
    proc_event(p, SKE_PROC_EV_STOP);
}

void CREATE_PROCESS(
    /*in */ PROCESS_ATTRIBUTE_TYPE *ATTRIBUTES,
    /*out*/ PROCESS_ID_TYPE *PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex__check_in(ATTRIBUTES, sizeof *ATTRIBUTES);
    apex__check_out(PROCESS_ID, sizeof *PROCESS_ID);
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
    apex__enter(RETURN_CODE);
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
    fresh_context(p);
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
    make_dormant(p);
    swapcontext(&p->ctx, &rt->sched_ctx);
    /* A dormant process is only resumed through START, which gives it a fresh context. */
}

void GET_MY_ID(
    /*out*/ PROCESS_ID_TYPE *PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex__check_out(PROCESS_ID, sizeof *PROCESS_ID);
    if (!apex__rt.current || apex__rt.current == &apex__rt.eh) {
        *RETURN_CODE = INVALID_MODE; /* the initialisation process and the error handler */
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
    apex__enter(RETURN_CODE);
    apex__check_name(PROCESS_NAME);
    apex__check_out(PROCESS_ID, sizeof *PROCESS_ID);
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
    apex__enter(RETURN_CODE);
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    apex__check_out(PROCESS_STATUS, sizeof *PROCESS_STATUS);
    PROCESS_STATUS->ATTRIBUTES = p->attr;
    PROCESS_STATUS->CURRENT_PRIORITY = p->cur_prio;
    PROCESS_STATUS->DEADLINE_TIME = p->deadline_time;
    PROCESS_STATUS->PROCESS_STATE = p->start_pending ? WAITING : p->state;
    *RETURN_CODE = NO_ERROR;
}

/* ---- Further process services (ARINC 653 Part 1, 3.3.2) ------------------------------- */

/* The state the standard sees: a process STARTed before NORMAL mode waits for it. */
static PROCESS_STATE_TYPE state_of(const apex_proc_t *p)
{
    return p->start_pending ? WAITING : p->state;
}

static bool is_periodic(const apex_proc_t *p) { return p->attr.PERIOD != INFINITE_TIME_VALUE; }

static bool is_suspended(const apex_proc_t *p)
{
    return p->suspended || (p->state == WAITING && p->wait == WAIT_SUSPEND);
}

/* The error handler is no ARINC process of the partition's: LOCK_PREEMPTION and
 * UNLOCK_PREEMPTION do nothing there. */
static bool current_is_process(void)
{
    return apex__rt.current && apex__rt.current != &apex__rt.eh;
}

void STOP(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p || p == apex__rt.current) {
        *RETURN_CODE = INVALID_PARAM; /* a process stops itself with STOP_SELF */
        return;
    }
    if (state_of(p) == DORMANT) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    make_dormant(p);
    *RETURN_CODE = NO_ERROR;
}

void SUSPEND_SELF(
    /*in */ SYSTEM_TIME_TYPE TIME_OUT,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    apex_proc_t *p = apex__rt.current;
    if (!apex__may_block()) {
        *RETURN_CODE = INVALID_MODE; /* preemption locked, error handler, initialisation */
        return;
    }
    int64_t until = INT64_MAX;
    if (TIME_OUT < INFINITE_TIME_VALUE ||
        (TIME_OUT > 0 && !apex__time_add(apex__now(), TIME_OUT, &until))) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (is_periodic(p)) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (TIME_OUT == 0) {
        *RETURN_CODE = NO_ERROR;
        return;
    }
    /* RESUME ends the wait with NO_ERROR; the time-out with TIMED_OUT. */
    p->wait = WAIT_SUSPEND;
    p->wake_at = until;
    *RETURN_CODE = apex__block(p);
}

void SUSPEND(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p || p == rt->current) {
        *RETURN_CODE = INVALID_PARAM; /* a process suspends itself with SUSPEND_SELF */
        return;
    }
    if ((rt->lock_level > 0 && p == rt->lock_owner) || state_of(p) == DORMANT ||
        is_periodic(p)) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (is_suspended(p)) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    /* A waiting process goes on waiting: its time-out still runs, and when its wait ends it
     * stays suspended until RESUME. */
    p->suspended = true;
    if (p->state == READY) {
        p->state = WAITING;
        p->wait = WAIT_NONE;
    }
    *RETURN_CODE = NO_ERROR;
}

void RESUME(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p || p == rt->current) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (state_of(p) == DORMANT || is_periodic(p)) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    if (!is_suspended(p)) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (p->state == WAITING && p->wait == WAIT_SUSPEND) {
        p->wait_rc = NO_ERROR; /* SUSPEND_SELF returns NO_ERROR */
        p->wake_at = INT64_MAX;
        apex__make_ready(p);
    } else {
        p->suspended = false;
        if (p->state == WAITING && p->wait == WAIT_NONE)
            apex__make_ready(p); /* not waiting for anything else */
    }
    *RETURN_CODE = NO_ERROR;
    apex__preempt_check();
}

void SET_PRIORITY(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*in */ PRIORITY_TYPE PRIORITY_VALUE, /* the standard's PRIORITY, also a discipline */
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p || PRIORITY_VALUE < MIN_PRIORITY_VALUE || PRIORITY_VALUE > MAX_PRIORITY_VALUE) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (state_of(p) == DORMANT) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    p->cur_prio = PRIORITY_VALUE;
    *RETURN_CODE = NO_ERROR;
    if (p != rt->current) {
        if (p->state == READY)
            p->ready_order = ++rt->order; /* the newest of its new priority */
        apex__preempt_check();
        return;
    }
    /* The caller itself becomes the newest process of its new priority: a ready process of
     * that priority or above runs first, unless preemption is locked. */
    p->ready_order = ++rt->order;
    if (rt->lock_level > 0 || rt->mode != NORMAL)
        return;
    for (int i = 0; i < rt->n_procs; i++)
        if (rt->procs[i].state == READY && rt->procs[i].cur_prio >= p->cur_prio) {
            p->state = READY;
            swapcontext(&p->ctx, &rt->sched_ctx);
            return;
        }
}

void apex__release_delayed(apex_proc_t *p, int64_t now, int64_t first_release)
{
    int64_t delay = p->start_delay, release;
    p->start_delay = 0;
    p->state = WAITING;
    p->deadline_time = INFINITE_TIME_VALUE;
    if (!is_periodic(p)) {
        /* Released at now + DELAY_TIME, its deadline counted from there. */
        p->wait = WAIT_DELAY;
        p->wake_at = apex__time_add(now, delay, &release) ? release : INT64_MAX;
        int64_t deadline;
        if (p->wake_at != INT64_MAX && p->attr.TIME_CAPACITY != INFINITE_TIME_VALUE &&
            apex__time_add(p->wake_at, p->attr.TIME_CAPACITY, &deadline))
            p->deadline_time = deadline;
    } else {
        /* First released DELAY_TIME after the partition's next period start. */
        p->wait = WAIT_PERIOD;
        p->wake_at = apex__time_add(first_release, delay, &release) ? release : INT64_MAX;
    }
}

void DELAYED_START(
    /*in */ PROCESS_ID_TYPE PROCESS_ID,
    /*in */ SYSTEM_TIME_TYPE DELAY_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex_proc_t *p = proc_by_id(PROCESS_ID);
    if (!p) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (p->state != DORMANT || p->start_pending) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    int64_t now = apex__now(), release;
    if (DELAY_TIME < 0 || !apex__time_add(now, DELAY_TIME, &release) ||
        (is_periodic(p) && DELAY_TIME >= p->attr.PERIOD)) {
        *RETURN_CODE = INVALID_PARAM; /* negative, infinite, or not within the period */
        return;
    }
    if (DELAY_TIME == 0) {
        START(PROCESS_ID, RETURN_CODE);
        return;
    }
    if (is_periodic(p))
        release = apex__time_add(apex__next_period_start(now), DELAY_TIME, &release) ? release
                                                                                      : INT64_MAX;
    int64_t deadline;
    if (rt->mode == NORMAL && p->attr.TIME_CAPACITY != INFINITE_TIME_VALUE &&
        (release == INT64_MAX || !apex__time_add(release, p->attr.TIME_CAPACITY, &deadline))) {
        *RETURN_CODE = INVALID_CONFIG; /* the deadline time is out of range */
        return;
    }
    fresh_context(p);
    p->start_delay = DELAY_TIME;
    proc_event(p, SKE_PROC_EV_START);
    if (rt->mode != NORMAL) {
        /* The delay runs from the partition's entry into NORMAL mode. */
        p->start_pending = true;
        *RETURN_CODE = NO_ERROR;
        return;
    }
    apex__release_delayed(p, now, apex__next_period_start(now));
    *RETURN_CODE = NO_ERROR;
}

void LOCK_PREEMPTION(
    /*out*/ LOCK_LEVEL_TYPE *LOCK_LEVEL,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex__check_out(LOCK_LEVEL, sizeof *LOCK_LEVEL);
    if (!current_is_process() || rt->mode != NORMAL) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (rt->lock_level >= MAX_LOCK_LEVEL) {
        *RETURN_CODE = INVALID_CONFIG;
        return;
    }
    rt->lock_level++;
    rt->lock_owner = rt->current;
    *LOCK_LEVEL = rt->lock_level;
    *RETURN_CODE = NO_ERROR;
}

void UNLOCK_PREEMPTION(
    /*out*/ LOCK_LEVEL_TYPE *LOCK_LEVEL,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex__check_out(LOCK_LEVEL, sizeof *LOCK_LEVEL);
    if (!current_is_process() || rt->mode != NORMAL || rt->lock_level == 0) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (--rt->lock_level == 0)
        rt->lock_owner = NULL;
    *LOCK_LEVEL = rt->lock_level;
    *RETURN_CODE = NO_ERROR;
    apex__preempt_check(); /* a higher-priority process made ready meanwhile runs now */
}
