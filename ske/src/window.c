/* SPDX-License-Identifier: Apache-2.0 */
/* One window of the cyclic plan: the grant to the partition, the wait for it to hand the
 * CPU back (or the overrun), its events into the trace, the queuing messages of its source
 * ports moved, and what the window's end leads to. */
#include "ske__supervisor.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#define HANG_FACTOR 20 /* emulated mode: a window may take this many times its length in wall */
#define HANG_MIN_NS 2000000000LL /* time (at least 2 s) while using no CPU before it is cut */
/* A partition that handed the CPU back has a few microseconds of system-call tail; more than
 * this much CPU before its next window means it went on computing. Above a scheduler tick
 * (4 ms at 250 Hz): the CPU clock of a process running on another CPU may lag by one. */
#define OUTSIDE_LIMIT_NS 5000000
#define RT_SPIN_NS 200000 /* real-time mode: spin this long before a window starts */

/* A spin-wait hint to the CPU (a sibling hyper-thread gets the pipeline meanwhile). */
static void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __asm__ __volatile__("pause" ::: "memory");
#elif defined(__aarch64__)
    __asm__ __volatile__("yield" ::: "memory");
#else
    atomic_signal_fence(memory_order_seq_cst);
#endif
}

typedef enum { W_YIELD, W_OVERRUN, W_EXIT, W_STOP } wres_t;

/* Why a window ended in an overrun (the trace's `cause`). */
typedef enum {
    OV_CPU_BUDGET, /* emulated: used the window's length in CPU time */
    OV_WALL_LIMIT, /* emulated: held the window far longer in wall time without using CPU */
    OV_WINDOW_END, /* real time: still running at the window's wall-clock end */
} ov_cause_t;

static const char *const ov_cause_names[] = {"cpu_budget", "wall_limit", "window_end"};

static bool yielded(const ske_part_t *p)
{
    return atomic_load_explicit(&p->ctl->yield_seq, memory_order_acquire) == p->grant_seq;
}

/* Waits for the partition to hand the CPU back. Emulated mode: the window's length is a
 * budget of CPU time (computation takes no emulated time, but it may not take unbounded
 * real time either). Real-time mode: the window ends at its wall-clock end. */
static wres_t wait_yield(ske_t *s, ske_part_t *p, int64_t budget_ns, int64_t end_mono_ns,
                         int64_t cpu0, ov_cause_t *cause)
{
    int64_t t0 = ske_mono_ns();
    /* No busy-waiting: the SKE sleeps on the futex at once and the partition's yield wakes
     * it. Pinned to one CPU, where flights run (one per CPU), a spinning SKE would only delay
     * the partition it waits for, and a window switch costs two context switches (≈ 7 µs
     * here). Floating over two CPUs the wake-up crosses CPUs (≈ 30 µs on these virtual
     * machines, where a 40 µs spin took 12 µs and burnt the other CPU meanwhile):
     * docs/performance.md. */
    for (;;) {
        if (yielded(p))
            return W_YIELD;
        if (s->child_event) {
            ske__reap(s);
            if (!ske__alive(p))
                return W_EXIT;
        }
        if (s->stop_signal)
            return W_STOP;
        int64_t now = ske_mono_ns();
        int64_t wait_ns;
        if (s->time_mode == SKE_TIME_REALTIME) {
            wait_ns = end_mono_ns - now;
            /* overrun-eats-next-window: wait for the yield, but not for ever (the same bound
             * as a blocked partition's in emulated mode). */
            if (wait_ns <= 0 && (!s->sw.eat_next_window || -wait_ns > HANG_MIN_NS)) {
                *cause = OV_WINDOW_END;
                return W_OVERRUN;
            }
            if (wait_ns <= 0)
                wait_ns = 10000000;
        } else {
            int64_t used = cpu0 >= 0 ? ske__cpu_now(p) - cpu0 : now - t0;
            /* Test switch overrun-eats-next-window: the budget is not enforced. */
            if (used >= budget_ns && !s->sw.eat_next_window) {
                *cause = OV_CPU_BUDGET;
                return W_OVERRUN;
            }
            int64_t hang = budget_ns * HANG_FACTOR > HANG_MIN_NS ? budget_ns * HANG_FACTOR : HANG_MIN_NS;
            if (now - t0 > hang) {
                *cause = OV_WALL_LIMIT; /* blocked without using its CPU: the plan cannot wait */
                return W_OVERRUN;
            }
            wait_ns = budget_ns - used;
            if (wait_ns > 10000000 || wait_ns <= 0)
                wait_ns = 10000000;
            if (wait_ns < 50000)
                wait_ns = 50000;
        }
        atomic_store(&p->ctl->ske_sleeping, 1);
        uint32_t v = atomic_load(&p->ctl->yield_seq);
        if (v != p->grant_seq) {
            struct timespec ts = {wait_ns / 1000000000LL, wait_ns % 1000000000LL};
            ske_futex_wait(&p->ctl->yield_seq, v, &ts);
        }
        atomic_store(&p->ctl->ske_sleeping, 0);
    }
}

/* Moves the messages a source queuing port holds to the destination's queue, as the core
 * software does at the end of the source's window (ARINC 653 Part 1, queuing mode). */
static void transfer_queues(ske_t *s, ske_part_t *p, int64_t t_ns)
{
    const ske_module_cfg_t *m = s->cfg;
    for (int k = 0; k < p->cfg->n_ports; k++) {
        const ske_port_cfg_t *pc = &p->cfg->ports[k];
        if (pc->kind != SKE_PORT_QUEUING || pc->dir != SKE_DIR_SOURCE || pc->channel < 0)
            continue;
        const ske_channel_cfg_t *ch = &m->channels[pc->channel];
        ske_part_t *dp = &s->parts[ch->dst[0].partition];
        const ske_port_cfg_t *dc = &dp->cfg->ports[ch->dst[0].port];
        ske_queue_hdr_t *sq = p->ports[k].mem;
        void *dq = dp->ports[ch->dst[0].port].mem;
        ske_port_desc_t *dd = &dp->ctl->ports[ch->dst[0].port];
        uint32_t stail = atomic_load(&sq->tail);
        uint32_t n = ske_queue_count(sq, pc->max_nb, stail);
        if (n == UINT32_MAX) {
            /* The source wrote inconsistent indices into its own queue: drop its content. */
            atomic_store(&sq->tail, atomic_load(&sq->head));
            ske_trace_begin(&s->trace, t_ns, "ske", "port");
            ske_trace_str(&s->trace, "event", "corrupt");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_str(&s->trace, "port", pc->name);
            ske_trace_end(&s->trace);
            continue;
        }
        uint8_t *buf = s->xfer;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t len;
            int64_t mt;
            ske_queue_peek(sq, pc->max_size, pc->max_nb, stail, buf, &len, &mt);
            stail++;
            ske__port_hash_queue(s, k, buf, len);
            uint32_t dtail = atomic_load(&dd->rx_tail);
            if (ske_queue_count(dq, dc->max_nb, dtail) == UINT32_MAX) {
                /* The destination corrupted its consumer index: resynchronise it. */
                atomic_store(&dd->rx_tail, atomic_load(&((ske_queue_hdr_t *)dq)->head));
                dtail = atomic_load(&dd->rx_tail);
            }
            /* Stamped with its arrival, the end of the source's window: a receiver whose
             * time-out comes later gets it, one whose time-out came first does not. */
            (void)mt;
            if (ske_queue_push(dq, dc->max_size, dc->max_nb, dtail, buf, len, t_ns)) {
                s->chan_messages[pc->channel]++;
            } else {
                atomic_fetch_add(&((ske_queue_hdr_t *)dq)->overflows, 1);
                s->chan_overflows[pc->channel]++;
                ske_trace_begin(&s->trace, t_ns, "ske", "port");
                ske_trace_str(&s->trace, "event", "overflow");
                ske_trace_str(&s->trace, "channel", ch->name);
                ske_trace_str(&s->trace, "partition", dp->cfg->name);
                ske_trace_str(&s->trace, "port", dc->name);
                ske_trace_end(&s->trace);
            }
        }
        atomic_store(&sq->tail, stail);
    }
}

/* Copies the partition's events into the trace. The ring is written by the partition, so
 * every field is checked; an event claiming a time outside the window is kept but marked. */
void ske__drain_events(ske_t *s, ske_part_t *p, int64_t win_start, int64_t win_end)
{
    ske_ctl_t *c = p->ctl;
    uint32_t head = atomic_load_explicit(&c->ev_head, memory_order_acquire);
    uint32_t tail = atomic_load(&c->ev_tail);
    uint32_t n = head - tail;
    if (n > SKE_EVENT_RING) {
        atomic_store(&c->ev_tail, head);
        return;
    }
    for (; tail != head; tail++) {
        ske_event_t e = c->ev[tail % SKE_EVENT_RING];
        int64_t t = e.t_ns;
        bool suspect = t < win_start || t > win_end;
        if (suspect)
            t = win_start;
        uint32_t len = e.len < SKE_EVENT_TEXT ? e.len : SKE_EVENT_TEXT;
        switch (e.kind) {
        case SKE_EV_MODE:
            if (e.a < 0 || e.a > 3 || e.b < 0 || e.b > 3)
                continue;
            ske_trace_begin(&s->trace, t, p->cfg->name, "mode");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_str(&s->trace, "mode", ske__mode_name((uint32_t)e.a));
            ske_trace_str(&s->trace, "from", ske__mode_name((uint32_t)e.b));
            break;
        case SKE_EV_PORT_VALIDITY:
            if (e.a < 0 || e.a >= p->cfg->n_ports)
                continue;
            ske_trace_begin(&s->trace, t, p->cfg->name, "port");
            ske_trace_str(&s->trace, "event", e.b ? "valid" : "invalid");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_str(&s->trace, "port", p->cfg->ports[e.a].name);
            break;
        case SKE_EV_APP_MESSAGE:
            ske_trace_begin(&s->trace, t, p->cfg->name, "app_message");
            ske_trace_int(&s->trace, "process", e.a);
            ske_trace_strn(&s->trace, "text", e.text, len);
            break;
        case SKE_EV_HM: {
            /* Decided in the partition: its error handler takes the error. */
            hm_error_t he = (hm_error_t)e.a;
            if (!hm_error_name(he) || len < SKE_NAME_MAX)
                continue;
            char pname[SKE_NAME_MAX];
            memcpy(pname, e.text, sizeof pname);
            pname[sizeof pname - 1] = '\0';
            ske__trace_hm_fields(s, t, p, he, HM_LEVEL_PROCESS, HM_ACT_ERROR_HANDLER,
                                 HM_STATE_PROCESS, e.b, pname, e.text + SKE_NAME_MAX,
                                 len - SKE_NAME_MAX, NULL);
            break;
        }
        case SKE_EV_FAULT:
            /* Traced whole by fault.c, suspect time or not: its time places it in a spell. */
            ske__fault_event(s, p, t, e.a, e.b, e.text, len);
            continue;
        case SKE_EV_PROCESS:
            ske_trace_begin(&s->trace, t, p->cfg->name, "process");
            ske_trace_int(&s->trace, "process", e.a);
            ske_trace_strn(&s->trace, "name", e.text, strnlen(e.text, len));
            ske_trace_str(&s->trace, "event", e.b == SKE_PROC_EV_START ? "start" : "stop");
            break;
        default:
            continue;
        }
        if (suspect) {
            ske_trace_bool(&s->trace, "suspect_time", true);
            ske_trace_int(&s->trace, "reported_t_ns", e.t_ns);
        }
        ske_trace_end(&s->trace);
    }
    atomic_store(&c->ev_tail, head);
    uint32_t dropped = atomic_exchange(&c->ev_dropped, 0);
    if (dropped) {
        ske_trace_begin(&s->trace, win_end, "ske", "events_dropped");
        ske_trace_str(&s->trace, "partition", p->cfg->name);
        ske_trace_int(&s->trace, "count", dropped);
        ske_trace_end(&s->trace);
    }
}

int ske__run_window(ske_t *s, const ske_slot_t *slot, char *err, size_t errlen)
{
    const ske_window_cfg_t *w = slot->window;
    ske_part_t *p = &s->parts[w->partition];
    int64_t frame = slot->frame;
    int64_t start = slot->start_ns;
    int64_t end = slot->end_ns;
    s->now_ns = start;
    s->win_end_ns = end;
    s->cur_partition = -1;
    bool rt = s->time_mode == SKE_TIME_REALTIME;
    int64_t start_mono = s->epoch_mono_ns + start;
    int64_t late = 0;
    if (rt) {
        /* Sleep until shortly before the window, then spin to its exact start: a sleeping
         * thread wakes tens of microseconds late, a spinning one within a microsecond. */
        int64_t wake = start_mono - RT_SPIN_NS;
        struct timespec ts = {wake / 1000000000LL, wake % 1000000000LL};
        while (ske_mono_ns() < wake &&
               clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
            if (s->stop_signal)
                return SKE_OK;
            if (s->child_event)
                ske__reap(s);
        }
        while (ske_mono_ns() < start_mono)
            cpu_relax();
        late = ske_mono_ns() - start_mono;
    }
    if (s->child_event)
        ske__reap(s);
    /* overrun-eats-next-window (emulated mode): this window starts when the last window's
     * partition let the CPU go, if that is after its start; what is left of it is the
     * budget. */
    int64_t eaten = 0;
    if (!rt && s->cpu_held_until_ns > start) {
        late = s->cpu_held_until_ns - start;
        eaten = late < w->duration_ns ? late : w->duration_ns;
    }
    s->cpu_held_until_ns = 0;
    ske__switches_window_start(s, start);

    ske_trace_begin(&s->trace, start, "ske", "window_start");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_int(&s->trace, "window", w->id);
    ske_trace_int(&s->trace, "frame", frame);
    if (!ske__alive(p))
        ske_trace_str(&s->trace, "partition_state", ske__pstate_name(p->state));
    if (rt || late > 0)
        ske_trace_int(&s->trace, "late_ns", late);
    if (!rt && (s->bus.flags & CANBUS_WELCOME_REALTIME) && s->bus.ticked) {
        /* Lockstep on a bus paced by the wall clock: how long after its wall-clock time this
         * window starts (0 when the node is ahead of the clock, as it runs each quantum's
         * windows as soon as the bus grants it). */
        int64_t wl = ske_mono_ns() - s->bus.tick_mono_ns + s->bus.tick_late_ns -
                     (start - s->bus.tick_start_ns);
        ske_trace_int(&s->trace, "wall_late_ns", wl > 0 ? wl : 0);
    }
    ske_trace_end(&s->trace);
    ske__faults_window_start(s, p, start);
    ske__faults_output(s, p, start);

    wres_t r = W_EXIT;
    ov_cause_t cause = OV_CPU_BUDGET;
    bool granted = false;
    int64_t outside_ns = 0; /* CPU the partition used since it last handed the CPU back */
    if (ske__alive(p) && eaten < w->duration_ns) {
        granted = true;
        s->cur_partition = w->partition;
        int64_t cpu0 = ske__cpu_now(p);
        if (p->cpu_at_yield_ns >= 0 && cpu0 >= 0) {
            outside_ns = cpu0 - p->cpu_at_yield_ns;
            if (outside_ns > p->cpu_outside_max_ns)
                p->cpu_outside_max_ns = outside_ns;
        }
        if (outside_ns > OUTSIDE_LIMIT_NS) {
            /* It handed the CPU back but went on computing between its windows (the
             * kernel's accounting says so): time taken from the other partitions. */
            ske_trace_begin(&s->trace, start, "ske", "overrun");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_int(&s->trace, "window", w->id);
            ske_trace_int(&s->trace, "frame", frame);
            ske_trace_str(&s->trace, "cause", "outside_window");
            ske_trace_str(&s->trace, "action", "reported");
            ske_trace_end(&s->trace);
            p->overruns++;
        }
        if (p->state == SKE_PS_STOPPED) {
            kill(p->pid, SIGCONT);
            p->state = SKE_PS_RUNNING;
        }
        ske__port_hash_grant(s, p);
        int64_t budget = w->duration_ns - eaten;
        atomic_store(&p->ctl->win_start_ns, start + eaten);
        atomic_store(&p->ctl->win_end_ns, end);
        p->grant_seq++;
        atomic_store_explicit(&p->ctl->grant_seq, p->grant_seq, memory_order_release);
        ske_futex_wake(&p->ctl->grant_seq);
        p->windows++;
        pid_t granted_pid = p->pid;
        r = wait_yield(s, p, budget, s->epoch_mono_ns + end, cpu0, &cause);
        /* A partition that posted an error waits for the decision: take it now and, if the
         * partition goes on (IGNORE), give it the rest of its window, still on the same
         * CPU budget. What it reported before the error comes first in the trace. */
        while (r == W_YIELD && ske__alive(p) &&
               atomic_load(&p->ctl->hm_seq) != atomic_load(&p->ctl->hm_ack)) {
            ske__drain_events(s, p, start, end);
            int64_t at = p->ctl->hm_t_ns;
            at = at < start ? start : at > end ? end : at;
            pid_t before = p->pid;
            int hrc = ske__hm_take_post(s, p, at, err, errlen);
            if (hrc != SKE_OK)
                return hrc;
            /* Idled, shut down, or restarted (a new process starts in its next window). */
            if (!ske__alive(p) || s->hm_shutdown || p->pid != before)
                break;
            p->grant_seq++;
            atomic_store_explicit(&p->ctl->grant_seq, p->grant_seq, memory_order_release);
            ske_futex_wake(&p->ctl->grant_seq);
            r = wait_yield(s, p, budget, s->epoch_mono_ns + end, cpu0, &cause);
        }
        /* A process restarted by the health monitor has a clock of its own: this window's
         * accounting is the granted process's only. */
        bool same = p->pid == granted_pid;
        int64_t cpu1 = same ? ske__cpu_now(p) : -1;
        if (r == W_OVERRUN) {
            /* No waiting for the stop to take effect: a process with SIGSTOP pending cannot
             * return to user space, so it computes nothing more whether it is on a CPU now or
             * waiting for one; waiting for it could only delay the next window. A stop that
             * has not landed yet when the partition's next window comes is discarded by
             * that window's SIGCONT. */
            kill(p->pid, SIGSTOP);
            if (yielded(p)) {
                kill(p->pid, SIGCONT); /* it handed the CPU back in the instant before */
                r = W_YIELD;
            } else {
                p->state = SKE_PS_STOPPED;
                p->overruns++;
            }
        }
        if (cpu0 >= 0 && cpu1 >= 0)
            p->cpu_ns += cpu1 - cpu0;
        if (s->sw.eat_next_window && !rt && cpu0 >= 0 && cpu1 >= 0 && cpu1 - cpu0 > budget)
            s->cpu_held_until_ns = end + (cpu1 - cpu0 - budget);
        p->cpu_at_yield_ns = r == W_YIELD && same ? cpu1 : -1;
        if (r == W_YIELD && same) {
            int64_t wake = atomic_load(&p->ctl->wake_mono_ns);
            int64_t yield = atomic_load(&p->ctl->yield_mono_ns);
            if (rt) {
                int64_t j = wake - start_mono;
                if (j > -1000000000LL && j < 1000000000LL)
                    ske_samples_add(&s->jitter_ns, j < 0 ? 0 : j);
            } else if (s->prev_yield_mono_ns > 0) {
                int64_t sw = wake - s->prev_yield_mono_ns;
                if (sw > 0 && sw < 1000000000LL)
                    ske_samples_add(&s->switch_ns, sw);
            }
            s->prev_yield_mono_ns = yield;
        } else {
            s->prev_yield_mono_ns = 0;
        }
    } else {
        s->prev_yield_mono_ns = 0;
    }

    /* In time order: what the partition reported inside its window, then what happened at
     * the window's end. */
    if (granted && p->ctl)
        ske__drain_events(s, p, start, end);
    int rc = SKE_OK;
    if (r == W_OVERRUN) {
        ske_trace_begin(&s->trace, end, "ske", "overrun");
        ske_trace_str(&s->trace, "partition", p->cfg->name);
        ske_trace_int(&s->trace, "window", w->id);
        ske_trace_int(&s->trace, "frame", frame);
        ske_trace_int(&s->trace, "budget_ns", w->duration_ns);
        ske_trace_str(&s->trace, "cause", ov_cause_names[cause]);
        ske_trace_str(&s->trace, "action", "stopped");
        ske_trace_end(&s->trace);
    }
    if (granted && p->ctl) {
        transfer_queues(s, p, end);
        ske__port_hash_end(s, p, end);
    }
    if (r == W_YIELD && ske__alive(p))
        rc = ske__hm_take_post(s, p, end, err, errlen);
    if (rc == SKE_OK && r == W_YIELD && ske__alive(p))
        ske__take_schedule_request(s, p, end);
    if (rc == SKE_OK && outside_ns > OUTSIDE_LIMIT_NS && ske__alive(p)) {
        char msg[96];
        int n = snprintf(msg, sizeof msg, "used CPU between its windows before window %d", w->id);
        rc = ske__hm_handle(s, p, end, HM_ERR_WINDOW_OVERRUN, ske__partition_state(p),
                            HM_ORIGIN_SKE, 0, NULL, msg, (size_t)n, false, err, errlen);
    }
    if (rc == SKE_OK && r == W_OVERRUN && ske__alive(p)) {
        char msg[80];
        int n = snprintf(msg, sizeof msg, "window %d kept past its end (budget %lld ns)", w->id,
                         (long long)w->duration_ns);
        /* IGNORE leaves it stopped until its next window; IDLE or a restart end it now. */
        rc = ske__hm_handle(s, p, end, HM_ERR_WINDOW_OVERRUN, ske__partition_state(p),
                            HM_ORIGIN_SKE, 0, NULL, msg, (size_t)n, false, err, errlen);
    }
    if (rc == SKE_OK)
        rc = ske__judge_exits(s, end, err, errlen);
    s->cur_partition = -1;
    ske_trace_begin(&s->trace, end, "ske", "window_end");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_int(&s->trace, "window", w->id);
    ske_trace_int(&s->trace, "frame", frame);
    if (granted) {
        ske_trace_bool(&s->trace, "yielded", r == W_YIELD);
        if (r == W_YIELD && !rt) {
            int64_t yt = atomic_load(&p->ctl->yield_t_ns);
            if (yt >= start && yt <= end)
                ske_trace_int(&s->trace, "yield_t_ns", yt);
        }
    }
    ske_trace_end(&s->trace);
    if (rc != SKE_OK)
        return rc;
    if (r == W_YIELD && ske__alive(p))
        return ske__handle_mode_request(s, p, end, err, errlen);
    return SKE_OK;
}
