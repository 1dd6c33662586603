/* SPDX-License-Identifier: Apache-2.0 */
/* The CAN wire model: arbitration, frame timing, error frames, fault confinement; the faults
 * act through the hooks of faultinject/can/canbus__fault.h. */
#include "canbus__wire.h"

#include <stdlib.h>
#include <string.h>

#define NS_PER_S 1000000000ull

int canbus_wire_init(canbus_wire_t *w, uint32_t bitrate, uint32_t gap_bits)
{
    memset(w, 0, sizeof *w);
    if (bitrate < 1000 || bitrate > 10000000)
        return CANBUS_WIRE_EINVAL;
    w->bitrate = bitrate;
    w->gap_bits = gap_bits;
    return 0;
}

void canbus_wire_fini(canbus_wire_t *w)
{
    free(w->future.v);
    free(w->ready.v);
    free(w->faults);
    free(w->ev);
    free(w->win_busy);
    memset(w, 0, sizeof *w);
}

/* Split into seconds so that nothing overflows 64 bits for any run length. */
uint64_t canbus_wire_bit_ceil(const canbus_wire_t *w, int64_t ns)
{
    if (ns <= 0)
        return 0;
    uint64_t s = (uint64_t)ns / NS_PER_S, r = (uint64_t)ns % NS_PER_S;
    return s * w->bitrate + (r * w->bitrate + NS_PER_S - 1) / NS_PER_S;
}

int64_t canbus_wire_bit_ns(const canbus_wire_t *w, uint64_t bit)
{
    uint64_t s = bit / w->bitrate, r = bit % w->bitrate;
    return (int64_t)(s * NS_PER_S + r * NS_PER_S / w->bitrate);
}

uint32_t canbus_wire_arb_key(uint32_t id, uint8_t flags)
{
    uint32_t rtr = (flags & CANBUS_FRAME_RTR) ? 1u : 0u;
    if (flags & CANBUS_FRAME_EFF) {
        uint32_t base = (id >> 18) & 0x7FFu, ext = id & 0x3FFFFu;
        return base << 21 | 1u << 20 /* SRR */ | 1u << 19 /* IDE */ | ext << 1 | rtr;
    }
    return (id & 0x7FFu) << 21 | rtr << 20; /* IDE = 0 and nothing after it competes */
}

uint32_t canbus_wire_frame_bits(uint8_t flags, uint8_t len)
{
    /* A remote frame has a DLC but no data field. */
    return canbus_frame_bits(flags & CANBUS_FRAME_EFF, (flags & CANBUS_FRAME_RTR) ? 0 : len);
}

/* ---- heaps ------------------------------------------------------------------------------ */

static bool future_before(const canbus_wire_frame_t *a, const canbus_wire_frame_t *b)
{
    return a->req_bit != b->req_bit ? a->req_bit < b->req_bit : a->seq < b->seq;
}

static bool ready_before(const canbus_wire_frame_t *a, const canbus_wire_frame_t *b)
{
    if (a->key != b->key)
        return a->key < b->key;
    if (a->client != b->client)
        return a->client < b->client;
    return a->seq < b->seq;
}

typedef bool (*heap_less_t)(const canbus_wire_frame_t *, const canbus_wire_frame_t *);

static int heap_push(canbus_wire_heap_t *h, const canbus_wire_frame_t *f, heap_less_t less)
{
    if (h->n == h->cap) {
        size_t cap = h->cap ? h->cap * 2 : 256;
        canbus_wire_frame_t *v = realloc(h->v, cap * sizeof *v);
        if (!v)
            return CANBUS_WIRE_ENOMEM;
        h->v = v;
        h->cap = cap;
    }
    size_t i = h->n++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!less(f, &h->v[p]))
            break;
        h->v[i] = h->v[p];
        i = p;
    }
    h->v[i] = *f;
    return 0;
}

static void heap_sift_down(canbus_wire_heap_t *h, size_t i, heap_less_t less)
{
    canbus_wire_frame_t x = h->v[i];
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && less(&h->v[c + 1], &h->v[c]))
            c++;
        if (!less(&h->v[c], &x))
            break;
        h->v[i] = h->v[c];
        i = c;
    }
    h->v[i] = x;
}

static void heap_pop(canbus_wire_heap_t *h, heap_less_t less)
{
    if (--h->n > 0) {
        h->v[0] = h->v[h->n];
        heap_sift_down(h, 0, less);
    }
}

/* Removes the frames of `client` requested at or before bit `at`, calling out() on each,
 * and restores the heap. */
static void heap_remove_client(canbus_wire_heap_t *h, uint8_t client, uint64_t at,
                               heap_less_t less, canbus_wire_t *w, int64_t at_ns,
                               void (*out)(canbus_wire_t *, const canbus_wire_frame_t *, int64_t))
{
    size_t k = 0;
    for (size_t i = 0; i < h->n; i++) {
        if (h->v[i].client == client && h->v[i].req_bit <= at)
            out(w, &h->v[i], at_ns);
        else
            h->v[k++] = h->v[i];
    }
    h->n = k;
    for (size_t i = h->n / 2; i-- > 0;)
        heap_sift_down(h, i, less);
}

/* ---- events, load ----------------------------------------------------------------------- */

canbus_wire_ev_t *canbus__wire_ev(canbus_wire_t *w)
{
    if (w->n_ev == w->cap_ev) {
        /* Keep what the caller has not consumed or not seen (ev_mark) yet. */
        size_t s = w->ev_head < w->ev_mark ? w->ev_head : w->ev_mark;
        if (s > w->cap_ev / 2) {
            memmove(w->ev, w->ev + s, (w->n_ev - s) * sizeof *w->ev);
            w->n_ev -= s;
            w->ev_head -= s;
            w->ev_mark -= s;
        } else {
            size_t cap = w->cap_ev ? w->cap_ev * 2 : 1024;
            canbus_wire_ev_t *v = realloc(w->ev, cap * sizeof *v);
            if (!v)
                return NULL;
            w->ev = v;
            w->cap_ev = cap;
        }
    }
    canbus_wire_ev_t *e = &w->ev[w->n_ev++];
    memset(e, 0, sizeof *e);
    return e;
}

static int add_busy(canbus_wire_t *w, uint64_t from, uint64_t to)
{
    w->busy_bits += to - from;
    while (from < to) {
        size_t k = (size_t)(from / w->bitrate);
        uint64_t wend = (uint64_t)(k + 1) * w->bitrate;
        uint64_t piece = (to < wend ? to : wend) - from;
        if (k >= w->n_win) {
            size_t n = k + 16;
            uint64_t *v = realloc(w->win_busy, n * sizeof *v);
            if (!v)
                return CANBUS_WIRE_ENOMEM;
            memset(v + w->n_win, 0, (n - w->n_win) * sizeof *v);
            w->win_busy = v;
            w->n_win = n;
        }
        w->win_busy[k] += piece;
        from += piece;
    }
    return 0;
}

void canbus_wire_load(const canbus_wire_t *w, int64_t elapsed_ns, double *overall,
                      double *max_1s)
{
    uint64_t bits = canbus_wire_bit_ceil(w, elapsed_ns);
    *overall = bits ? (double)w->busy_bits / (double)bits : 0.0;
    if (*overall > 1.0) /* a frame still on the wire at the end */
        *overall = 1.0;
    size_t complete = (size_t)(bits / w->bitrate);
    double best = complete ? 0.0 : *overall;
    for (size_t k = 0; k < complete && k < w->n_win; k++) {
        double l = (double)w->win_busy[k] / (double)w->bitrate;
        if (l > best)
            best = l;
    }
    *max_1s = best;
}

/* ---- fault confinement ------------------------------------------------------------------ */

enum canbus_err_state canbus_wire_state(const canbus_wire_t *w, uint8_t client)
{
    if (client >= CANBUS_WIRE_MAX_CLIENTS)
        return CANBUS_ERR_ACTIVE;
    const canbus_wire_ctl_t *c = &w->ctl[client];
    if (c->bus_off)
        return CANBUS_ERR_BUS_OFF;
    if (c->tec >= 128 || c->rec >= 128)
        return CANBUS_ERR_PASSIVE;
    return CANBUS_ERR_ACTIVE;
}

static void note_client(canbus_wire_t *w, uint8_t client)
{
    if (client < CANBUS_WIRE_MAX_CLIENTS && client >= w->n_ctl)
        w->n_ctl = (uint16_t)(client + 1);
}

void canbus_wire_attach(canbus_wire_t *w, uint8_t client, bool attached)
{
    if (client >= CANBUS_WIRE_MAX_CLIENTS || w->ctl[client].attached == attached)
        return;
    note_client(w, client);
    w->ctl[client].attached = attached;
    if (attached) {
        w->receivers[w->n_receivers++] = client;
        return;
    }
    for (size_t i = 0; i < w->n_receivers; i++) {
        if (w->receivers[i] == client) {
            memmove(&w->receivers[i], &w->receivers[i + 1], w->n_receivers - i - 1);
            w->n_receivers--;
            break;
        }
    }
}

void canbus_wire_arm_recovery(canbus_wire_t *w, uint8_t client, bool recover)
{
    if (client < CANBUS_WIRE_MAX_CLIENTS) {
        note_client(w, client);
        w->ctl[client].recover = recover;
    }
}

void canbus__wire_drop(canbus_wire_t *w, const canbus_wire_frame_t *f, int64_t at_ns,
                       uint16_t fault)
{
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    w->dropped++;
    if (f->client < CANBUS_WIRE_MAX_CLIENTS) {
        w->ctl[f->client].dropped++;
        w->ctl[f->client].pending--;
    }
    if (!e)
        return;
    e->kind = CANBUS_EV_DROP;
    e->client = f->client;
    e->state = (uint8_t)canbus_wire_state(w, f->client);
    e->reason = (f->client < CANBUS_WIRE_MAX_CLIENTS && w->ctl[f->client].bus_off)
                    ? CANBUS_DROP_BUS_OFF
                    : CANBUS_DROP_FAULT;
    e->fault = e->reason == CANBUS_DROP_FAULT ? fault : 0;
    e->id = f->id;
    e->flags = f->flags;
    e->len = f->len;
    e->start_ns = e->end_ns = at_ns;
    memcpy(e->data, f->data, 8);
}

static void drop_bus_off(canbus_wire_t *w, const canbus_wire_frame_t *f, int64_t at_ns)
{
    canbus__wire_drop(w, f, at_ns, 0);
}

void canbus__wire_bus_off(canbus_wire_t *w, uint8_t client, uint64_t at_bit, bool forced)
{
    canbus_wire_ctl_t *c = &w->ctl[client];
    int64_t at_ns = canbus_wire_bit_ns(w, at_bit);
    c->bus_off = true;
    c->bus_off_events++;
    w->n_bus_off++;
    c->recover_bit = at_bit + CANBUS_RECOVERY_BITS;
    w->bus_off_events++;
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    if (e) {
        e->kind = CANBUS_EV_BUS_OFF;
        e->client = client;
        e->state = CANBUS_ERR_BUS_OFF;
        e->reason = forced ? 1 : 0;
        e->tec = c->tec;
        e->id = CANBUS_ANY_ID;
        e->start_ns = e->end_ns = at_ns;
    }
    /* A bus-off controller sends nothing: what it had queued is lost; frames requested for
     * later are dropped at their time unless it has recovered by then. */
    heap_remove_client(&w->ready, client, at_bit, ready_before, w, at_ns, drop_bus_off);
    heap_remove_client(&w->future, client, at_bit, future_before, w, at_ns, drop_bus_off);
}

void canbus__wire_bus_on(canbus_wire_t *w, uint8_t client, uint64_t at_bit)
{
    canbus_wire_ctl_t *ctl = &w->ctl[client];
    if (!ctl->bus_off)
        return;
    w->n_bus_off--;
    ctl->bus_off = false;
    ctl->tec = ctl->rec = 0;
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    if (e) {
        e->kind = CANBUS_EV_BUS_ON;
        e->client = client;
        e->state = CANBUS_ERR_ACTIVE;
        e->id = CANBUS_ANY_ID;
        e->start_ns = e->end_ns = canbus_wire_bit_ns(w, at_bit);
    }
}

/* State changes due at or before bit b: recoveries, then what the faults force. */
static int apply_due(canbus_wire_t *w, uint64_t b)
{
    for (unsigned c = 0; w->n_bus_off && c < w->n_ctl; c++) {
        canbus_wire_ctl_t *ctl = &w->ctl[c];
        if (ctl->bus_off && ctl->recover && ctl->recover_bit <= b)
            canbus__wire_bus_on(w, (uint8_t)c, b);
    }
    return w->n_faults ? canbus__fault_due(w, b) : 0;
}

/* The next bit after b at which something may become ready, or UINT64_MAX. */
static uint64_t next_wake(const canbus_wire_t *w, uint64_t b)
{
    uint64_t t = UINT64_MAX;
    if (w->future.n && w->future.v[0].req_bit < t)
        t = w->future.v[0].req_bit;
    for (unsigned c = 0; w->n_bus_off && c < w->n_ctl; c++) {
        const canbus_wire_ctl_t *ctl = &w->ctl[c];
        if (ctl->bus_off && ctl->recover && ctl->recover_bit < t)
            t = ctl->recover_bit;
    }
    if (w->n_faults) {
        uint64_t f = canbus__fault_wake(w, b);
        if (f < t)
            t = f;
    }
    return t;
}

int canbus__wire_requeue(canbus_wire_t *w, const canbus_wire_frame_t *f)
{
    return heap_push(&w->future, f, future_before);
}

/* Moves the frames requested at or before bit b to the arbitration set; the drop and delay
 * faults act here (on the request time). */
static int release_due(canbus_wire_t *w, uint64_t b)
{
    while (w->future.n && w->future.v[0].req_bit <= b) {
        canbus_wire_frame_t f = w->future.v[0];
        heap_pop(&w->future, future_before);
        if (f.client < CANBUS_WIRE_MAX_CLIENTS && w->ctl[f.client].bus_off) {
            canbus__wire_drop(w, &f, canbus_wire_bit_ns(w, b), 0);
            continue;
        }
        if (w->n_faults) {
            enum canbus_release what;
            if (canbus__fault_release(w, &f, b, &what))
                return CANBUS_WIRE_ENOMEM;
            if (what != CANBUS_RELEASE_PASS)
                continue;
        }
        if (heap_push(&w->ready, &f, ready_before))
            return CANBUS_WIRE_ENOMEM;
    }
    return 0;
}

static void fill_ev(canbus_wire_ev_t *e, const canbus_wire_frame_t *f, uint8_t kind)
{
    e->kind = kind;
    e->client = f->client;
    e->id = f->id;
    e->flags = f->flags;
    e->len = f->len;
    memcpy(e->data, f->data, 8);
}

/* A corrupted transmission of f at bit b: the error frame, the counters, perhaps bus-off.
 * Receivers see a CRC error and flag it after the ACK delimiter (ISO 11898-1 §10.11); the
 * frame stays queued and competes again. */
static int error_frame(canbus_wire_t *w, const canbus_wire_frame_t *f, uint64_t b, uint16_t fault)
{
    uint32_t bits = canbus_wire_frame_bits(f->flags, f->len);
    canbus_wire_ctl_t *ctl = f->client < CANBUS_WIRE_MAX_CLIENTS ? &w->ctl[f->client] : NULL;
    uint64_t end = b + bits - CANBUS_EOF_IFS_BITS + CANBUS_ERROR_FRAME_BITS + CANBUS_IFS_BITS +
                   w->gap_bits;
    w->error_frames++;
    for (size_t i = 0; i < w->n_receivers; i++) {
        canbus_wire_ctl_t *r = &w->ctl[w->receivers[i]];
        if (w->receivers[i] != f->client && !r->bus_off && r->rec < 255)
            r->rec++;
    }
    if (ctl) {
        ctl->tec = (uint16_t)(ctl->tec + 8);
        ctl->tx_err++;
    }
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    if (!e)
        return CANBUS_WIRE_ENOMEM;
    fill_ev(e, f, CANBUS_EV_ERROR);
    e->fault = fault;
    e->start_ns = canbus_wire_bit_ns(w, b);
    e->end_ns = canbus_wire_bit_ns(w, end);
    e->tec = ctl ? ctl->tec : 0;
    e->state = (uint8_t)(ctl && ctl->tec > 255 ? CANBUS_ERR_BUS_OFF
                                               : canbus_wire_state(w, f->client));
    if (add_busy(w, b, end))
        return CANBUS_WIRE_ENOMEM;
    w->free_bit = end;
    /* A receiver whose transceiver is cut does not see the error frame either. */
    if (w->n_faults && canbus__fault_after_tx(w, w->n_ev - 1, false))
        return CANBUS_WIRE_ENOMEM;
    if (ctl && ctl->tec > 255)
        canbus__wire_bus_off(w, f->client, end, false);
    return 0;
}

/* A good transmission of f at bit b, delivered to the receivers. */
static int transmit(canbus_wire_t *w, const canbus_wire_frame_t *f, uint64_t b, uint16_t fault,
                    uint8_t reason)
{
    uint32_t bits = canbus_wire_frame_bits(f->flags, f->len);
    uint64_t end = b + bits;
    canbus_wire_ctl_t *ctl = f->client < CANBUS_WIRE_MAX_CLIENTS ? &w->ctl[f->client] : NULL;
    if (ctl) {
        if (ctl->tec)
            ctl->tec--;
        ctl->tx_ok++;
    }
    for (size_t i = 0; i < w->n_receivers; i++) {
        canbus_wire_ctl_t *r = &w->ctl[w->receivers[i]];
        if (w->receivers[i] != f->client && r->rec)
            r->rec = r->rec > 127 ? 127 : (uint16_t)(r->rec - 1);
    }
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    if (!e)
        return CANBUS_WIRE_ENOMEM;
    fill_ev(e, f, CANBUS_EV_TX);
    e->fault = fault;
    e->reason = reason;
    e->start_ns = canbus_wire_bit_ns(w, b);
    e->end_ns = canbus_wire_bit_ns(w, end);
    e->tec = ctl ? ctl->tec : 0;
    e->state = (uint8_t)canbus_wire_state(w, f->client);
    w->frames++;
    w->frame_bits += bits;
    if (add_busy(w, b, end))
        return CANBUS_WIRE_ENOMEM;
    w->free_bit = end + w->gap_bits;
    return 0;
}

int canbus_wire_run(canbus_wire_t *w, int64_t until_ns)
{
    uint64_t until_bit = canbus_wire_bit_ceil(w, until_ns);
    bool faults = w->n_faults > 0;
    while (w->free_bit < until_bit) {
        uint64_t b = w->free_bit;
        if (faults && canbus__fault_close_spells(w, canbus_wire_bit_ns(w, b)))
            return CANBUS_WIRE_ENOMEM;
        if (apply_due(w, b) || release_due(w, b))
            return CANBUS_WIRE_ENOMEM;

        if (w->dup_pending) {
            /* A duplicate follows its original at once, without arbitration, as the same
             * controller's retransmission would. */
            canbus_wire_frame_t d = w->dup;
            w->dup_pending = false;
            if (d.client < CANBUS_WIRE_MAX_CLIENTS && w->ctl[d.client].bus_off)
                continue;
            w->duplicated++;
            if (transmit(w, &d, b, w->dup_fault, CANBUS_TX_DUPLICATE) ||
                canbus__fault_after_tx(w, w->n_ev - 1, false))
                return CANBUS_WIRE_ENOMEM;
            continue;
        }

        canbus_wire_frame_t bab;
        canbus_fault_t *bf = faults ? canbus__fault_babbler(w, b, &bab) : NULL;
        bool from_ready = w->ready.n && (!bf || ready_before(&w->ready.v[0], &bab));
        if (!from_ready && !bf) {
            uint64_t next = next_wake(w, b);
            w->free_bit = next < until_bit ? (next > b ? next : b + 1) : until_bit;
            continue;
        }
        canbus_wire_frame_t f = from_ready ? w->ready.v[0] : bab;
        int64_t start_ns = canbus_wire_bit_ns(w, b);
        uint16_t fault = 0;
        if (faults && from_ready) {
            if (canbus__fault_cut(w, &f, start_ns, &fault))
                return CANBUS_WIRE_ENOMEM;
            if (fault) {
                heap_pop(&w->ready, ready_before);
                canbus__wire_drop(w, &f, start_ns, fault);
                continue;
            }
        }
        if (faults) {
            if (canbus__fault_corrupt(w, &f, start_ns, &fault))
                return CANBUS_WIRE_ENOMEM;
            if (fault) {
                if (error_frame(w, &f, b, fault))
                    return CANBUS_WIRE_ENOMEM;
                continue;
            }
        }
        if (from_ready) {
            heap_pop(&w->ready, ready_before);
            if (f.client < CANBUS_WIRE_MAX_CLIENTS)
                w->ctl[f.client].pending--;
        } else {
            if (canbus__fault_babbled(w, bf, b))
                return CANBUS_WIRE_ENOMEM;
            fault = (uint16_t)(bf - w->faults + 1);
        }
        if (transmit(w, &f, b, fault, 0))
            return CANBUS_WIRE_ENOMEM;
        if (faults && canbus__fault_after_tx(w, w->n_ev - 1, true))
            return CANBUS_WIRE_ENOMEM;
    }
    if (faults && canbus__fault_close_spells(w, until_ns))
        return CANBUS_WIRE_ENOMEM;
    return 0;
}

int canbus_wire_submit(canbus_wire_t *w, int64_t req_ns, uint32_t id, uint8_t flags,
                       uint8_t len, const uint8_t *data, uint8_t client)
{
    if (len > 8 || client >= CANBUS_WIRE_MAX_CLIENTS)
        return CANBUS_WIRE_EINVAL;
    if (id > ((flags & CANBUS_FRAME_EFF) ? 0x1FFFFFFFu : 0x7FFu))
        return CANBUS_WIRE_EINVAL;
    if (w->ctl[client].pending >= CANBUS_WIRE_MAX_PENDING)
        return CANBUS_WIRE_EFULL;
    note_client(w, client);
    canbus_wire_frame_t f = {0};
    f.req_ns = req_ns < 0 ? 0 : req_ns;
    f.req_bit = canbus_wire_bit_ceil(w, f.req_ns);
    f.seq = w->seq++;
    f.id = id;
    f.flags = flags & (CANBUS_FRAME_EFF | CANBUS_FRAME_RTR);
    f.len = len;
    f.client = client;
    f.key = canbus_wire_arb_key(id, f.flags);
    if (data && len)
        memcpy(f.data, data, len);
    int rc = heap_push(&w->future, &f, future_before);
    if (rc == 0)
        w->ctl[client].pending++;
    return rc;
}

int canbus_wire_add_fault(canbus_wire_t *w, const canbus_fault_t *f)
{
    if (f->kind < 1 || f->kind > CANBUS_FAULT_KINDS)
        return CANBUS_WIRE_EINVAL;
    if (f->kind == CANBUS_FAULT_BABBLE && f->babble_len > 8)
        return CANBUS_WIRE_EINVAL;
    if (f->period_ns < 0 || (f->period_ns > 0 && (f->on_ns <= 0 || f->on_ns > f->period_ns)))
        return CANBUS_WIRE_EINVAL;
    if (w->n_faults == w->cap_faults) {
        size_t cap = w->cap_faults ? w->cap_faults * 2 : 8;
        canbus_fault_t *v = realloc(w->faults, cap * sizeof *v);
        if (!v)
            return CANBUS_WIRE_ENOMEM;
        w->faults = v;
        w->cap_faults = cap;
    }
    if (w->n_faults >= UINT16_MAX - 1)
        return CANBUS_WIRE_EFULL; /* events name a fault by a 16-bit index */
    note_client(w, f->target);
    canbus_fault_t *g = &w->faults[w->n_faults++];
    *g = *f;
    g->used = 0;
    g->spell = g->last_spell = -1;
    g->spell_hits = 0;
    g->forced_spell = -1;
    return 0;
}
