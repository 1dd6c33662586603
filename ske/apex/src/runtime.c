/* SPDX-License-Identifier: Apache-2.0 */
/* The APEX run-time of a partition: attaches to the SKE before main() runs, schedules the
 * partition's ARINC processes one at a time, and hands the CPU back when all of them wait. */
#include "apex__rt.h"
#include "apex__sandbox.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

apex_rt_t apex__rt;

static void fatal(const char *msg)
{
    fprintf(stderr, "%s\n", msg);
    _exit(2);
}

/* ---- hand-over with the SKE ----------------------------------------------------------- */

static void take_grant(void)
{
    apex_rt_t *rt = &apex__rt;
    ske_ctl_t *c = rt->ctl;
    rt->seen_grant = atomic_load_explicit(&c->grant_seq, memory_order_acquire);
    atomic_store(&c->wake_mono_ns, ske_mono_ns());
    rt->win_start = atomic_load(&c->win_start_ns);
    rt->win_end = atomic_load(&c->win_end_ns);
    if (!rt->realtime && rt->now < rt->win_start)
        rt->now = rt->win_start;
}

static void wait_grant(void)
{
    ske_ctl_t *c = apex__rt.ctl;
    uint32_t seen = apex__rt.seen_grant;
    while (atomic_load_explicit(&c->grant_seq, memory_order_acquire) == seen)
        ske_futex_wait(&c->grant_seq, seen, NULL);
    take_grant();
}

void apex__yield_cpu(void)
{
    apex_rt_t *rt = &apex__rt;
    ske_ctl_t *c = rt->ctl;
    /* Yield for the window we hold now, even if we were stopped and continued into a later
     * one after an overrun. */
    uint32_t g = atomic_load_explicit(&c->grant_seq, memory_order_acquire);
    if (g != rt->seen_grant)
        take_grant();
    atomic_store(&c->yield_t_ns, apex__now());
    atomic_store(&c->yield_mono_ns, ske_mono_ns());
    /* Sequentially consistent store then load, against the SKE's store of ske_sleeping then
     * load of yield_seq: one of the two always sees the other, so no wake-up is lost, and
     * the system call is saved when the SKE has not gone to sleep yet. */
    atomic_store(&c->yield_seq, rt->seen_grant);
    if (atomic_load(&c->ske_sleeping))
        ske_futex_wake(&c->yield_seq);
    wait_grant();
}

/* Runs before main() and before the partition's own constructors (101 is the first priority
 * a program may use): the partition's code starts inside its first window, under its system-
 * call filter, holding no port descriptor. */
__attribute__((constructor(101))) static void apex_attach(void)
{
    const char *s = getenv(SKE_ENV_CTL_FD);
    if (!s)
        fatal("this program is an ARINC 653 partition: run it under ima-ske "
              "(for example: ./ima run MODULE.xml)");
    char *end;
    long fd = strtol(s, &end, 10);
    if (*end || fd < 0)
        fatal("apex: bad " SKE_ENV_CTL_FD);
    void *m = mmap(NULL, sizeof(ske_ctl_t), PROT_READ | PROT_WRITE, MAP_SHARED, (int)fd, 0);
    if (m == MAP_FAILED)
        fatal("apex: cannot map the SKE control block");
    close((int)fd);
    unsetenv(SKE_ENV_CTL_FD);
    apex_rt_t *rt = &apex__rt;
    rt->ctl = m;
    if (rt->ctl->magic != SKE_ABI_MAGIC || rt->ctl->version != SKE_ABI_VERSION ||
        rt->ctl->ctl_size != sizeof(ske_ctl_t))
        fatal("apex: this partition was built against another version of the SKE's partition "
              "interface: rebuild it");
    rt->realtime = rt->ctl->time_mode == SKE_TIME_REALTIME;
    if (rt->realtime)
        prctl(PR_SET_TIMERSLACK, 1UL); /* time-outs inside a window wake on time */
    rt->mode = (OPERATING_MODE_TYPE)rt->ctl->initial_mode;
    rt->seen_grant = 0;
    /* Standard output is ima-ske's (a pipe or a file more often than a terminal), which the C
     * library would buffer fully: a partition killed or restarted by the health monitor would
     * lose what it printed, and partitions' lines would mix in 4 KiB pieces. Line buffering
     * writes each complete line at once, in one write for lines up to 4 KiB. */
    setvbuf(stdout, NULL, _IOLBF, 0);
    apex__ports_attach();
    apex__hm_init();
    apex__faults_init();
#ifdef IMA_COVERAGE
    apex__coverage_init();
#endif
    if (apex__sandbox_install(rt->ctl) != 0)
        fatal("apex: cannot install the partition's system-call filter");
    atomic_store(&rt->ctl->ready, 1);
    ske_futex_wake(&rt->ctl->ready);
    wait_grant();
    if (rt->realtime)
        rt->now = ske_mono_ns() - rt->ctl->epoch_mono_ns;
}

/* ---- time ----------------------------------------------------------------------------- */

int64_t apex__now(void)
{
    apex_rt_t *rt = &apex__rt;
    if (rt->realtime)
        rt->now = ske_mono_ns() - rt->ctl->epoch_mono_ns;
    return rt->now;
}

static void release_due(void);

void apex__refresh_time(void)
{
    apex_rt_t *rt = &apex__rt;
    if (atomic_load_explicit(&rt->ctl->grant_seq, memory_order_acquire) != rt->seen_grant)
        take_grant(); /* we were stopped after an overrun and continued in a new window */
    if (rt->realtime)
        apex__now();
}

void apex__sync(void)
{
    apex_rt_t *rt = &apex__rt;
    apex__refresh_time();
    if (rt->realtime && rt->mode == NORMAL) {
        /* Time moves while processes compute: releases that fell due preempt the running
         * process at this service call. */
        release_due();
        apex__preempt_check();
    }
    /* One comparison when no fault is due: every service call passes here. */
    if (__builtin_expect(rt->now >= rt->fault_due, 0))
        apex__fault_point();
}

int64_t apex__next_period_start(int64_t t)
{
    const ske_ctl_t *c = apex__rt.ctl;
    int64_t period = c->period_ns > 0 ? c->period_ns : c->major_frame_ns;
    int64_t anchor = c->period_anchor_ns;
    if (t <= anchor)
        return anchor;
    int64_t k = (t - anchor + period - 1) / period;
    return anchor + k * period;
}

/* ---- events --------------------------------------------------------------------------- */

uint32_t apex__event_room(void)
{
    ske_ctl_t *c = apex__rt.ctl;
    uint32_t used = atomic_load_explicit(&c->ev_head, memory_order_relaxed) -
                    atomic_load_explicit(&c->ev_tail, memory_order_acquire);
    return used < SKE_EVENT_RING ? SKE_EVENT_RING - used : 0;
}

void apex__event(uint32_t kind, int32_t a, int32_t b, const void *text, uint32_t len)
{
    ske_ctl_t *c = apex__rt.ctl;
    uint32_t head = atomic_load_explicit(&c->ev_head, memory_order_relaxed);
    uint32_t tail = atomic_load_explicit(&c->ev_tail, memory_order_acquire);
    if (head - tail >= SKE_EVENT_RING) {
        atomic_fetch_add(&c->ev_dropped, 1);
        return;
    }
    ske_event_t *e = &c->ev[head % SKE_EVENT_RING];
    e->t_ns = apex__now();
    e->kind = kind;
    e->a = a;
    e->b = b;
    if (len > SKE_EVENT_TEXT)
        len = SKE_EVENT_TEXT;
    e->len = len;
    if (len)
        memcpy(e->text, text, len);
    atomic_store_explicit(&c->ev_head, head + 1, memory_order_release);
}

/* ---- process scheduler ---------------------------------------------------------------- */

void apex__make_ready(apex_proc_t *p)
{
    p->wait = WAIT_NONE;
    if (p->suspended) {
        p->state = WAITING; /* its wait is over, its suspension lasts until RESUME */
        return;
    }
    p->state = READY;
    p->ready_order = ++apex__rt.order;
}

/* Highest current priority first, FIFO (time it became ready) within a priority; the error
 * handler before any process (ARINC 653 Part 1: it has the highest priority). */
static apex_proc_t *pick(void)
{
    apex_rt_t *rt = &apex__rt;
    if (rt->lock_owner && rt->lock_owner->state == DORMANT) {
        rt->lock_level = 0; /* its holder was stopped by a fault: the lock went with it */
        rt->lock_owner = NULL;
    }
    if (rt->has_eh && rt->eh.state == READY)
        return &rt->eh;
    if (rt->lock_level > 0 && rt->lock_owner && rt->lock_owner->state == READY)
        return rt->lock_owner; /* preemption is locked: its holder goes on */
    apex_proc_t *best = NULL;
    for (int i = 0; i < rt->n_procs; i++) {
        apex_proc_t *p = &rt->procs[i];
        if (p->state != READY)
            continue;
        if (!best || p->cur_prio > best->cur_prio ||
            (p->cur_prio == best->cur_prio && p->ready_order < best->ready_order))
            best = p;
    }
    return best;
}

bool apex__may_block(void)
{
    const apex_rt_t *rt = &apex__rt;
    return rt->current && rt->current != &rt->eh && rt->lock_level == 0;
}

static void release(apex_proc_t *p)
{
    if (p->wait == WAIT_PERIOD) {
        p->deadline_missed = false; /* a new release, a new deadline */
        int64_t r = p->wake_at;
        p->deadline_time = INFINITE_TIME_VALUE;
        if (p->attr.TIME_CAPACITY != INFINITE_TIME_VALUE &&
            !apex__time_add(r, p->attr.TIME_CAPACITY, &p->deadline_time))
            p->deadline_time = INFINITE_TIME_VALUE;
        if (!apex__time_add(r, p->attr.PERIOD, &p->next_release))
            p->next_release = INT64_MAX; /* the end of the clock: no further release */
        p->wait_rc = NO_ERROR;
    } else if (p->wait == WAIT_DELAY) {
        p->wait_rc = NO_ERROR;
    } else {
        p->wait_rc = TIMED_OUT; /* a queuing wait ran out; outputs stay untouched */
    }
    p->wake_at = INT64_MAX;
    apex__make_ready(p);
}

/* Processes whose time has come, in time order then process order, so that the FIFO
 * order of simultaneous releases is deterministic. */
static void release_due(void)
{
    apex_rt_t *rt = &apex__rt;
    for (;;) {
        apex_proc_t *first = NULL;
        for (int i = 0; i < rt->n_procs; i++) {
            apex_proc_t *p = &rt->procs[i];
            if (p->state == WAITING && p->wake_at <= rt->now && (!first || p->wake_at < first->wake_at))
                first = p;
        }
        if (!first)
            return;
        release(first);
    }
}

static int64_t next_event(void)
{
    apex_rt_t *rt = &apex__rt;
    int64_t t = INT64_MAX;
    for (int i = 0; i < rt->n_procs; i++)
        if (rt->procs[i].state == WAITING && rt->procs[i].wake_at < t)
            t = rt->procs[i].wake_at;
    return t;
}

static void run(apex_proc_t *p)
{
    apex_rt_t *rt = &apex__rt;
    rt->current = p;
    p->state = RUNNING;
    swapcontext(&rt->sched_ctx, &p->ctx);
    rt->current = NULL;
}

static void sleep_until(int64_t t)
{
    int64_t abs_ns = apex__rt.ctl->epoch_mono_ns + t;
    struct timespec ts = {abs_ns / 1000000000LL, abs_ns % 1000000000LL};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
    }
}

/* The scheduler runs on the initialisation process's stack once the partition is NORMAL.
 * Emulated time: computation takes no time, so time moves only here, to the next release
 * or time-out inside the window; past the window, the CPU goes back to the SKE. */
static void __attribute__((noreturn)) scheduler_loop(void)
{
    apex_rt_t *rt = &apex__rt;
    for (;;) {
        apex__sync();
        /* Port waits first: a message that arrived (or a slot that freed) before a waiter's
         * time-out wins over the time-out, even when both are past by now. */
        apex__service_port_waiters();
        release_due();
        apex__hm_check_deadlines();
        apex_proc_t *p = pick();
        if (p) {
            run(p);
            continue;
        }
        int64_t next = next_event();
        if (next < rt->win_end) {
            if (rt->realtime)
                sleep_until(next);
            else
                rt->now = next;
            continue;
        }
        apex__yield_cpu();
    }
}

RETURN_CODE_TYPE apex__block(apex_proc_t *p)
{
    p->state = WAITING;
    swapcontext(&p->ctx, &apex__rt.sched_ctx);
    return p->wait_rc;
}

void apex__preempt_check(void)
{
    apex_rt_t *rt = &apex__rt;
    apex_proc_t *cur = rt->current;
    if (!cur || rt->mode != NORMAL)
        return;
    apex_proc_t *p = pick();
    if (p && p != cur &&
        (p == &rt->eh || (cur != &rt->eh && rt->lock_level == 0 && p->cur_prio > cur->cur_prio))) {
        /* The preempted process keeps its place: it has been ready the longest. */
        cur->state = READY;
        swapcontext(&cur->ctx, &rt->sched_ctx);
    }
}

void apex__enter_normal(void)
{
    apex_rt_t *rt = &apex__rt;
    OPERATING_MODE_TYPE prev = rt->mode;
    rt->mode = NORMAL;
    atomic_store(&rt->ctl->mode, NORMAL);
    apex__event(SKE_EV_MODE, NORMAL, prev, NULL, 0);
    int64_t now = apex__now();
    int64_t first_release = apex__next_period_start(now);
    for (int i = 0; i < rt->n_procs; i++) {
        apex_proc_t *p = &rt->procs[i];
        if (!p->start_pending)
            continue;
        p->start_pending = false;
        if (p->start_delay > 0) {
            apex__release_delayed(p, now, first_release); /* DELAYED_START (process.c) */
            continue;
        }
        if (p->attr.PERIOD == INFINITE_TIME_VALUE) {
            /* A deadline past the end of the clock is no deadline (the health monitor's
             * illegal-request report for it comes with the HM tables). */
            p->deadline_time = INFINITE_TIME_VALUE;
            if (p->attr.TIME_CAPACITY != INFINITE_TIME_VALUE &&
                !apex__time_add(now, p->attr.TIME_CAPACITY, &p->deadline_time))
                p->deadline_time = INFINITE_TIME_VALUE;
            apex__make_ready(p);
        } else {
            p->state = WAITING;
            p->wait = WAIT_PERIOD;
            p->wake_at = first_release;
        }
    }
    scheduler_loop();
}
