/* SPDX-License-Identifier: Apache-2.0 */
/* The fault hook: the faults the SKE armed in the control block (ima-ske --fault) are
 * committed by the partition itself, in its own context, at the first service call one of its
 * processes (the named one, if the fault names one) makes at or after their time. Each is
 * recorded as a fault event before the partition misbehaves, so that the record reaches the
 * trace even when the misbehaviour ends the process; whatever the misbehaviour triggers (a
 * signal, the SKE's overrun detection, the deadline check, the health monitor) is the
 * product's real detection. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>

#include "apex__rt.h"
#include "fi/partition.h"
#include "fi/spec.h"

typedef struct {
    const ske_fault_slot_t *slot; /* NULL: an empty slot */
    fi_spec_t spec; /* its spell times, as faultinject reads them */
    int64_t done_spell; /* the last spell applied or refused, in this process or before */
    bool active; /* a state fault applied in spell active_spell and not cleared */
    int64_t active_spell;
    bool here; /* ... applied in this process too (after a restart, not yet) */
    int64_t flood_window; /* queuing_flood: the window it last filled its queue in */
} apex_fault_t;

static apex_fault_t faults[SKE_FAULT_SLOTS];
static int n_faults;

/* ---- time ------------------------------------------------------------------------------ */

static int64_t add_sat(int64_t a, int64_t b) { return b > 0 && a > INT64_MAX - b ? INT64_MAX : a + b; }

static int64_t mul_sat(int64_t a, int64_t b) { return a != 0 && b > INT64_MAX / a ? INT64_MAX : a * b; }

/* When spell k ends (INT64_MAX: never). */
static int64_t spell_end(const fi_spec_t *sp, int64_t k)
{
    int64_t end = sp->until_ns;
    if (sp->duration == FI_INTERMITTENT) {
        int64_t e = add_sat(add_sat(sp->at_ns, mul_sat(k, sp->period_ns)), sp->on_ns);
        end = e < end ? e : end;
    }
    return end;
}

/* The first spell start after now (INT64_MAX: none). */
static int64_t next_spell_start(const fi_spec_t *sp, int64_t now)
{
    if (now < sp->at_ns)
        return sp->at_ns;
    if (sp->duration != FI_INTERMITTENT)
        return INT64_MAX;
    int64_t start = add_sat(sp->at_ns, mul_sat((now - sp->at_ns) / sp->period_ns + 1, sp->period_ns));
    return start < sp->until_ns ? start : INT64_MAX;
}

/* From when the hook has something to do for this fault. */
static int64_t next_check(const apex_fault_t *f, int64_t now)
{
    if (!f->slot)
        return INT64_MAX;
    if (f->active) {
        if (!f->here)
            return now; /* to apply again in this new process */
        int64_t end = spell_end(&f->spec, f->active_spell);
        /* A flood fills its queue again in each window: due at once in a window it has not
         * filled it in yet, else from the next window on. */
        if (f->slot->cls == SKE_FAULT_QUEUING_FLOOD) {
            if (f->flood_window != apex__rt.win_start)
                return now;
            end = apex__rt.win_end < end ? apex__rt.win_end : end;
        }
        return end;
    }
    int64_t k = fi_spec_spell(&f->spec, now);
    if (k >= 0 && k > f->done_spell)
        return now; /* due: waiting for a service call of its process */
    return next_spell_start(&f->spec, now);
}

static void update_due(void)
{
    int64_t due = INT64_MAX;
    for (int i = 0; i < n_faults; i++) {
        int64_t t = next_check(&faults[i], apex__rt.now);
        due = t < due ? t : due;
    }
    apex__rt.fault_due = due;
}

void apex__faults_init(void)
{
    const ske_ctl_t *c = apex__rt.ctl;
    n_faults = c->n_faults <= SKE_FAULT_SLOTS ? (int)c->n_faults : 0;
    for (int i = 0; i < n_faults; i++) {
        const ske_fault_slot_t *sl = &c->faults[i];
        apex_fault_t *f = &faults[i];
        memset(f, 0, sizeof *f);
        if (sl->cls == SKE_FAULT_NONE || sl->cls >= SKE_FAULT_CLASSES || sl->duration > FI_INTERMITTENT)
            continue;
        f->slot = sl;
        f->spec.at_ns = sl->at_ns;
        f->spec.until_ns = sl->until_ns;
        f->spec.period_ns = sl->period_ns > 0 ? sl->period_ns : 1;
        f->spec.on_ns = sl->on_ns;
        f->spec.duration = (fi_duration_t)sl->duration;
        f->done_spell = sl->done_spell;
        f->active = sl->active && sl->done_spell >= 0;
        f->active_spell = sl->done_spell;
        f->flood_window = -1;
    }
    update_due();
}

/* ---- records ----------------------------------------------------------------------------- */

static bool post(int i, ske_fault_state_t state, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static bool post(int i, ske_fault_state_t state, const char *fmt, ...)
{
    if (apex__event_room() == 0)
        return false;
    char text[SKE_EVENT_TEXT];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    n = n < 0 ? 0 : n >= (int)sizeof text ? (int)sizeof text - 1 : n;
    apex__event(SKE_EV_FAULT, i, (int32_t)state, text, (uint32_t)n);
    return true;
}

/* The running ARINC process, the named one if the fault names one: who commits it. */
static bool eligible(const apex_fault_t *f)
{
    const apex_rt_t *rt = &apex__rt;
    const apex_proc_t *p = rt->current;
    if (rt->mode != NORMAL || !p || p == &rt->eh)
        return false;
    const char *want = f->slot->process;
    size_t n = strnlen(p->attr.NAME, MAX_NAME_LENGTH);
    return !want[0] || (strnlen(want, SKE_NAME_MAX) == n && memcmp(want, p->attr.NAME, n) == 0);
}

static const char *pname(void)
{
    static char name[MAX_NAME_LENGTH + 1];
    const apex_proc_t *p = apex__rt.current;
    size_t n = p ? strnlen(p->attr.NAME, MAX_NAME_LENGTH) : 0;
    memcpy(name, p ? p->attr.NAME : "", n);
    name[n] = '\0';
    return name;
}

/* ---- state faults ------------------------------------------------------------------------- */

/* The port a fault names, if it is one of the partition's of that kind and direction. */
static int fault_port(const apex_fault_t *f, uint32_t kind, uint32_t dir)
{
    const ske_ctl_t *c = apex__rt.ctl;
    int k = f->slot->port;
    if (k < 0 || (uint32_t)k >= c->n_ports || k >= SKE_MAX_PORTS || c->ports[k].kind != kind ||
        c->ports[k].dir != dir || !apex__rt.ports[k].mem)
        return -1;
    return k;
}

/* corrupt_output, stuck_output: what WRITE_SAMPLING_MESSAGE does on the port, on or off. */
static bool set_output(const apex_fault_t *f, bool on)
{
    int k = fault_port(f, SKE_PORT_SAMPLING, SKE_DIR_SOURCE);
    if (k < 0)
        return false;
    apex_port_t *ap = &apex__rt.ports[k];
    if (!on) {
        ap->out_fault = APEX_OUT_NORMAL;
        if (ap->fault_buf)
            munmap(ap->fault_buf, apex__rt.ctl->ports[k].max_size);
        ap->fault_buf = NULL;
        return true;
    }
    if (f->slot->cls == SKE_FAULT_CORRUPT_OUTPUT && !ap->fault_buf) {
        void *m = mmap(NULL, apex__rt.ctl->ports[k].max_size, PROT_READ | PROT_WRITE,
                       MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (m == MAP_FAILED)
            return false;
        ap->fault_buf = m;
    }
    ap->out_fault = f->slot->cls == SKE_FAULT_CORRUPT_OUTPUT ? APEX_OUT_CORRUPT : APEX_OUT_STUCK;
    return true;
}

bool apex__fault_write(int k, const APEX_BYTE *msg, MESSAGE_SIZE_TYPE len)
{
    apex_port_t *ap = &apex__rt.ports[k];
    if (ap->out_fault == APEX_OUT_STUCK)
        return true; /* nothing written: the port keeps its last message and goes stale */
    if (ap->out_fault != APEX_OUT_CORRUPT || !ap->fault_buf)
        return false;
    apex__user_copy(true);
    memcpy(ap->fault_buf, msg, (size_t)len);
    apex__user_copy(false);
    fi_corrupt_bytes(ap->fault_buf, (size_t)len);
    ske_sampling_write(ap->mem, apex__rt.ctl->ports[k].max_size, ap->fault_buf, (uint32_t)len,
                       apex__now());
    return true;
}

static bool flood_send(void *ctx)
{
    const apex_fault_t *f = ctx;
    int k = f->slot->port;
    APEX_BYTE msg[64] = {0};
    uint32_t len = apex__rt.ctl->ports[k].max_size < sizeof msg ? apex__rt.ctl->ports[k].max_size
                                                                : (uint32_t)sizeof msg;
    snprintf((char *)msg, sizeof msg, "flood %s", f->slot->fid);
    RETURN_CODE_TYPE rc;
    SEND_QUEUING_MESSAGE(k + 1, msg, (MESSAGE_SIZE_TYPE)len, 0, &rc);
    return rc == NO_ERROR;
}

/* queuing_flood: the source queue filled as fast as the partition can, until it refuses. */
static void flood(apex_fault_t *f)
{
    f->flood_window = apex__rt.win_start;
    fi_flood(flood_send, f, (int)apex__rt.ctl->ports[f->slot->port].max_nb + 1, true);
}

static bool clear(apex_fault_t *f, int i)
{
    if (!post(i, SKE_FAULT_CLEARED, "spell over: the partition behaves again"))
        return false;
    if (f->here && (f->slot->cls == SKE_FAULT_CORRUPT_OUTPUT || f->slot->cls == SKE_FAULT_STUCK_OUTPUT))
        set_output(f, false);
    f->active = false;
    f->here = false;
    return true;
}

/* partition_hang: the process spins without yielding, window after window (the SKE stops
 * it at each window's end), until its spell is over. */
static void hang(apex_fault_t *f, int i)
{
    apex_rt_t *rt = &apex__rt;
    for (;;) {
        fi_spin_cpu(200000);
        apex__refresh_time(); /* a new window's grant, after the SKE stopped and continued it */
        if (fi_spec_spell(&f->spec, rt->now) != f->active_spell && clear(f, i))
            break;
    }
}

/* Applies a state fault: first in its spell (recorded), or again in a new process of the
 * partition (restarted in the middle of the spell: already recorded). */
static void apply_state(apex_fault_t *f, int i, bool first)
{
    uint32_t cls = f->slot->cls;
    const ske_port_desc_t *d = f->slot->port >= 0 && f->slot->port < SKE_MAX_PORTS
                                   ? &apex__rt.ctl->ports[f->slot->port] : NULL;
    f->active = true;
    f->here = true;
    if (cls == SKE_FAULT_PARTITION_HANG) {
        if (first)
            post(i, SKE_FAULT_APPLIED, "process %s spins without yielding", pname());
        hang(f, i);
    } else if (cls == SKE_FAULT_QUEUING_FLOOD) {
        int k = fault_port(f, SKE_PORT_QUEUING, SKE_DIR_SOURCE);
        if (k < 0 || !apex__rt.ports[k].created) {
            f->active = f->here = false;
            post(i, SKE_FAULT_REFUSED, "port %s was never created", d ? d->name : "?");
            return;
        }
        if (first)
            post(i, SKE_FAULT_APPLIED, "process %s fills queuing port %s as fast as it can, in "
                 "every window", pname(), d->name);
        flood(f);
    } else if (!set_output(f, true)) {
        f->active = f->here = false;
        post(i, SKE_FAULT_REFUSED, "no memory for the output fault on port %s", d ? d->name : "?");
    } else if (first) {
        post(i, SKE_FAULT_APPLIED, cls == SKE_FAULT_CORRUPT_OUTPUT
                 ? "every WRITE_SAMPLING_MESSAGE on %s writes its bytes XOR 0x5A"
                 : "WRITE_SAMPLING_MESSAGE on %s writes nothing", d->name);
    }
}

/* ---- event faults ------------------------------------------------------------------------ */

static void miss_deadline(int i)
{
    apex_proc_t *p = apex__rt.current;
    if (p->deadline_time == INFINITE_TIME_VALUE || !apex__may_block()) {
        post(i, SKE_FAULT_REFUSED, "process %s %s", pname(),
             p->deadline_time == INFINITE_TIME_VALUE ? "has no deadline" : "may not wait now");
        return;
    }
    int64_t now = apex__now();
    int64_t delay = p->deadline_time >= now ? p->deadline_time - now + 1 : 1;
    post(i, SKE_FAULT_APPLIED, "process %s waits %lld ns (TIMED_WAIT), past its deadline at %lld ns",
         pname(), (long long)delay, (long long)p->deadline_time);
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(delay, &rc); /* the deadline check sees it still at work at its deadline */
}

static void commit(apex_fault_t *f, int i)
{
    const ske_ctl_t *c = apex__rt.ctl;
    const ske_fault_slot_t *sl = f->slot;
    switch ((ske_fault_class_t)sl->cls) {
    case SKE_FAULT_PARTITION_CRASH:
        post(i, SKE_FAULT_APPLIED, "process %s calls abort(): the process ends on SIGABRT", pname());
        fi_crash();
    case SKE_FAULT_CPU_OVERRUN:
        post(i, SKE_FAULT_APPLIED, "process %s spins %lld ns of CPU", pname(), (long long)sl->value_ns);
        fi_spin_cpu(sl->value_ns);
        apex__refresh_time();
        break;
    case SKE_FAULT_MEMORY_VIOLATION:
        post(i, SKE_FAULT_APPLIED, "process %s writes to address 0x10", pname());
        fi_memory_violation();
        break;
    case SKE_FAULT_NUMERIC_ERROR:
        post(i, SKE_FAULT_APPLIED, "process %s divides an integer by zero", pname());
        fi_numeric_error();
        break;
    case SKE_FAULT_STACK_OVERFLOW:
        post(i, SKE_FAULT_APPLIED, "process %s recurses into its stack's guard page", pname());
        fi_stack_overflow();
        break;
    case SKE_FAULT_ILLEGAL_REQUEST:
        post(i, SKE_FAULT_APPLIED, c->system_partition
                 ? "process %s calls kill(parent, 0): no partition may signal another process"
                 : "process %s calls socket(): only a system partition may", pname());
        fi_illegal_request(c->system_partition != 0);
        break;
    case SKE_FAULT_APPLICATION_ERROR: {
        char msg[64];
        int n = snprintf(msg, sizeof msg, "fault %s: application_error injected", sl->fid);
        post(i, SKE_FAULT_APPLIED, "process %s calls RAISE_APPLICATION_ERROR(\"%s\")", pname(), msg);
        RETURN_CODE_TYPE rc;
        RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE)msg, n, &rc);
        break;
    }
    case SKE_FAULT_DEADLINE_MISS:
        miss_deadline(i);
        break;
    case SKE_FAULT_MEMORY_EXHAUSTION: {
        /* Bounded past the limit, should the limit not stop it. */
        size_t mib = fi_exhaust_memory((size_t)(sl->value_ns >> 20) + 64);
        post(i, SKE_FAULT_APPLIED, "process %s allocated %zu MiB until malloc refused (its memory "
             "limit), then writes through the null pointer", pname(), mib);
        fi_write_through_null();
        break;
    }
    case SKE_FAULT_FOREIGN_PORT_WRITE: {
        int k = sl->port >= 0 && sl->port < SKE_MAX_PORTS && (uint32_t)sl->port < c->n_ports &&
                        c->ports[sl->port].dir == SKE_DIR_DESTINATION ? sl->port : -1;
        if (k < 0 || !apex__rt.ports[k].mem) {
            post(i, SKE_FAULT_REFUSED, "no mapping of a destination port to write into");
            break;
        }
        post(i, SKE_FAULT_APPLIED, "process %s writes into the read-only memory of destination "
             "port %s", pname(), c->ports[k].name);
        fi_write_byte(apex__rt.ports[k].mem);
        break;
    }
    case SKE_FAULT_PARTITION_HANG:
    case SKE_FAULT_CORRUPT_OUTPUT:
    case SKE_FAULT_STUCK_OUTPUT:
    case SKE_FAULT_QUEUING_FLOOD:
        apply_state(f, i, true);
        break;
    default:
        break;
    }
}

/* ---- the hook ---------------------------------------------------------------------------- */

void apex__fault_point(void)
{
    apex_rt_t *rt = &apex__rt;
    for (int i = 0; i < n_faults; i++) {
        apex_fault_t *f = &faults[i];
        if (!f->slot)
            continue;
        int64_t k = fi_spec_spell(&f->spec, rt->now);
        if (f->active && k != f->active_spell && !clear(f, i))
            continue; /* no room to record it: at the next call */
        if (f->active) {
            bool again = !f->here ||
                         (f->slot->cls == SKE_FAULT_QUEUING_FLOOD && f->flood_window != rt->win_start);
            if (again && eligible(f)) {
                update_due();
                if (!f->here)
                    apply_state(f, i, false);
                else
                    flood(f);
            }
            continue;
        }
        /* Two records may follow (applied, then cleared or an error's): room for both, or
         * the fault waits for the next window's empty ring. */
        if (k < 0 || k <= f->done_spell || !eligible(f) || apex__event_room() < 2)
            continue;
        f->done_spell = k;
        if (f->slot->cls == SKE_FAULT_PARTITION_HANG || f->slot->cls == SKE_FAULT_CORRUPT_OUTPUT ||
            f->slot->cls == SKE_FAULT_STUCK_OUTPUT || f->slot->cls == SKE_FAULT_QUEUING_FLOOD)
            f->active_spell = k;
        /* Before committing: the fault may end the process or never come back here. */
        update_due();
        commit(f, i);
    }
    update_due();
}
