/* SPDX-License-Identifier: Apache-2.0 */
/* The bus faults acting on the wire model: the hooks it calls at each step (canbus__fault.h),
 * and the `fault` events (applied, cleared) that say when each fault acted. */
#include <string.h>

#include "canbus__fault.h"
#include "canbus__wire.h"

static uint16_t ref(const canbus_wire_t *w, const canbus_fault_t *f)
{
    return (uint16_t)(f - w->faults + 1);
}

static int fault_event(canbus_wire_t *w, const canbus_fault_t *f, uint8_t state, int64_t t_ns,
                       uint8_t client, uint32_t id, uint32_t count)
{
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    if (!e)
        return CANBUS_WIRE_ENOMEM;
    e->kind = CANBUS_EV_FAULT;
    e->reason = state;
    e->fault = ref(w, f);
    e->client = client;
    e->id = id;
    e->start_ns = e->end_ns = t_ns;
    for (unsigned k = 0; k < 4; k++)
        e->data[k] = (uint8_t)(count >> (8 * k));
    return 0;
}

/* The fault acted at at_ns on a frame it matched at match_ns: its trace events, if due. */
static int note(canbus_wire_t *w, canbus_fault_t *f, int64_t match_ns, int64_t at_ns,
                uint8_t client, uint32_t id)
{
    canbus_fault_note_t n = canbus_fault_hit(f, match_ns);
    if (n.cleared && fault_event(w, f, CANBUS_FAULT_CLEARED,
                                 canbus_fault_spell_end(f, n.cleared_spell), client,
                                 CANBUS_ANY_ID, n.cleared_hits))
        return CANBUS_WIRE_ENOMEM;
    if (n.applied && fault_event(w, f, CANBUS_FAULT_APPLIED, at_ns, client, id, 0))
        return CANBUS_WIRE_ENOMEM;
    return 0;
}

int canbus__fault_release(canbus_wire_t *w, canbus_wire_frame_t *f, uint64_t b,
                          enum canbus_release *what)
{
    *what = CANBUS_RELEASE_PASS;
    int64_t at = canbus_wire_bit_ns(w, b);
    canbus_fault_t *flt =
        canbus_fault_find(w->faults, w->n_faults, CANBUS_FAULT_DROP, f->client, f->id, f->req_ns);
    if (flt) {
        flt->used++;
        if (note(w, flt, f->req_ns, at, f->client, f->id))
            return CANBUS_WIRE_ENOMEM;
        canbus__wire_drop(w, f, at, ref(w, flt));
        *what = CANBUS_RELEASE_DROPPED;
        return 0;
    }
    if (f->delayed)
        return 0;
    flt = canbus_fault_find(w->faults, w->n_faults, CANBUS_FAULT_DELAY, f->client, f->id,
                            f->req_ns);
    if (!flt)
        return 0;
    flt->used++;
    if (note(w, flt, f->req_ns, at, f->client, f->id))
        return CANBUS_WIRE_ENOMEM;
    f->delayed = 1;
    f->req_ns += flt->delay_ns;
    f->req_bit = canbus_wire_bit_ceil(w, f->req_ns);
    *what = CANBUS_RELEASE_DELAYED;
    return canbus__wire_requeue(w, f);
}

/* The clients a bus-off fault acts on: its target, or with `any` every receiver. */
static bool bus_off_target(const canbus_wire_t *w, const canbus_fault_t *f, unsigned c)
{
    return f->target == CANBUS_ANY ? w->ctl[c].attached : f->target == c;
}

int canbus__fault_due(canbus_wire_t *w, uint64_t b)
{
    int64_t t = canbus_wire_bit_ns(w, b);
    for (size_t i = 0; i < w->n_faults; i++) {
        canbus_fault_t *f = &w->faults[i];
        if (f->kind != CANBUS_FAULT_BUS_OFF || f->target == CANBUS_NOBODY)
            continue;
        int64_t k = canbus_fault_spell(f, t);
        if (f->forced_spell >= 0 && k != f->forced_spell) {
            /* The spell is over: the controllers it put bus-off are restarted (if they did
             * not recover by themselves meanwhile). */
            for (unsigned c = 0; c < w->n_ctl; c++)
                if (bus_off_target(w, f, c) && w->ctl[c].bus_off)
                    canbus__wire_bus_on(w, (uint8_t)c, b);
            f->forced_spell = -1;
        }
        if (k < 0 || k <= f->last_spell)
            continue;
        f->forced_spell = k;
        if (note(w, f, t, t, f->target, CANBUS_ANY_ID))
            return CANBUS_WIRE_ENOMEM;
        for (unsigned c = 0; c < w->n_ctl; c++) {
            canbus_wire_ctl_t *ctl = &w->ctl[c];
            if (!bus_off_target(w, f, c) || ctl->bus_off)
                continue;
            ctl->tec = 256;
            if (f->recover)
                ctl->recover = true;
            canbus__wire_bus_off(w, (uint8_t)c, b, true);
        }
    }
    return 0;
}

uint64_t canbus__fault_wake(const canbus_wire_t *w, uint64_t b)
{
    int64_t t = canbus_wire_bit_ns(w, b);
    uint64_t best = UINT64_MAX;
    for (size_t i = 0; i < w->n_faults; i++) {
        const canbus_fault_t *f = &w->faults[i];
        if (f->target == CANBUS_NOBODY)
            continue;
        bool wakes = f->kind == CANBUS_FAULT_BUS_OFF ||
                     (f->kind == CANBUS_FAULT_BABBLE && (f->limit == 0 || f->used < f->limit));
        if (!wakes)
            continue;
        int64_t edge = canbus_fault_next_edge(f, t);
        if (edge == INT64_MAX)
            continue;
        uint64_t bit = canbus_wire_bit_ceil(w, edge);
        if (bit < best)
            best = bit;
    }
    return best;
}

/* The transceiver_cut fault active on `client` at t, or NULL. */
static canbus_fault_t *cut_of(canbus_wire_t *w, uint8_t client, int64_t t)
{
    for (size_t i = 0; i < w->n_faults; i++) {
        canbus_fault_t *f = &w->faults[i];
        if (f->kind == CANBUS_FAULT_CUT && f->target == client && canbus_fault_spell(f, t) >= 0)
            return f;
    }
    return NULL;
}

canbus_fault_t *canbus__fault_babbler(canbus_wire_t *w, uint64_t b, canbus_wire_frame_t *out)
{
    canbus_fault_t *best = NULL;
    int64_t t = canbus_wire_bit_ns(w, b);
    for (size_t i = 0; i < w->n_faults; i++) {
        canbus_fault_t *f = &w->faults[i];
        if (f->kind != CANBUS_FAULT_BABBLE || f->target == CANBUS_NOBODY ||
            canbus_fault_spell(f, t) < 0 || (f->limit && f->used >= f->limit))
            continue;
        if (f->target != CANBUS_ANY && (w->ctl[f->target].bus_off || cut_of(w, f->target, t)))
            continue;
        canbus_wire_frame_t c = {0};
        c.req_ns = t;
        c.req_bit = b;
        c.id = f->babble_id;
        c.flags = f->babble_flags;
        c.len = f->babble_len;
        c.client = f->target;
        c.key = canbus_wire_arb_key(c.id, c.flags);
        for (unsigned k = 0; k < 8; k++)
            c.data[k] = (uint8_t)(w->babble_count >> (8 * (k % 4)));
        if (!best || c.key < out->key || (c.key == out->key && c.client < out->client)) {
            best = f;
            *out = c;
        }
    }
    return best;
}

int canbus__fault_babbled(canbus_wire_t *w, canbus_fault_t *bf, uint64_t b)
{
    int64_t t = canbus_wire_bit_ns(w, b);
    bf->used++;
    w->babble_count++;
    return note(w, bf, t, t, bf->target, bf->babble_id);
}

int canbus__fault_cut(canbus_wire_t *w, const canbus_wire_frame_t *f, int64_t start_ns,
                      uint16_t *fault)
{
    *fault = 0;
    if (f->client > CANBUS_FAULT_MAX_INDEX)
        return 0;
    canbus_fault_t *flt = cut_of(w, f->client, start_ns);
    if (!flt)
        return 0;
    *fault = ref(w, flt);
    return note(w, flt, start_ns, start_ns, f->client, f->id);
}

int canbus__fault_corrupt(canbus_wire_t *w, const canbus_wire_frame_t *f, int64_t start_ns,
                          uint16_t *fault)
{
    canbus_fault_t *flt = canbus_fault_find(w->faults, w->n_faults, CANBUS_FAULT_CORRUPT,
                                            f->client, f->id, start_ns);
    *fault = 0;
    if (!flt)
        return 0;
    flt->used++;
    *fault = ref(w, flt);
    return note(w, flt, start_ns, start_ns, f->client, f->id);
}

/* Frame e is not delivered to `to` (a receiver, or CANBUS_ANY for every one). */
static int rx_drop(canbus_wire_t *w, const canbus_wire_ev_t *tx, canbus_fault_t *f, uint8_t to)
{
    if (note(w, f, tx->start_ns, tx->start_ns, tx->client, tx->id))
        return CANBUS_WIRE_ENOMEM;
    canbus_wire_ev_t *e = canbus__wire_ev(w);
    if (!e)
        return CANBUS_WIRE_ENOMEM;
    *e = *tx;
    e->kind = CANBUS_EV_RX_DROP;
    e->reason = 0;
    e->fault = ref(w, f);
    e->to = to;
    w->rx_dropped++;
    return 0;
}

int canbus__fault_after_tx(canbus_wire_t *w, size_t ev_index, bool may_duplicate)
{
    const canbus_wire_ev_t tx = w->ev[ev_index]; /* a copy: the list may move */
    int64_t t = tx.start_ns;
    for (size_t i = 0; i < w->n_faults; i++) {
        canbus_fault_t *f = &w->faults[i];
        uint8_t to = f->target;
        if (to == CANBUS_NOBODY || to == tx.client || canbus_fault_spell(f, t) < 0)
            continue;
        if (to != CANBUS_ANY && !w->ctl[to].attached)
            continue;
        if (f->kind == CANBUS_FAULT_RX_DROP && tx.kind == CANBUS_EV_TX) {
            if ((f->limit && f->used >= f->limit) ||
                (f->match_id != CANBUS_ANY_ID && f->match_id != tx.id))
                continue;
            f->used++;
            if (rx_drop(w, &tx, f, to))
                return CANBUS_WIRE_ENOMEM;
        } else if (f->kind == CANBUS_FAULT_CUT) {
            if (rx_drop(w, &tx, f, to))
                return CANBUS_WIRE_ENOMEM;
        }
    }
    if (!may_duplicate || tx.kind != CANBUS_EV_TX)
        return 0;
    canbus_fault_t *dup = canbus_fault_find(w->faults, w->n_faults, CANBUS_FAULT_DUPLICATE,
                                            tx.client, tx.id, t);
    if (!dup)
        return 0;
    dup->used++;
    if (note(w, dup, t, t, tx.client, tx.id))
        return CANBUS_WIRE_ENOMEM;
    canbus_wire_frame_t *d = &w->dup;
    memset(d, 0, sizeof *d);
    d->req_ns = tx.end_ns;
    d->id = tx.id;
    d->flags = tx.flags;
    d->len = tx.len;
    d->client = tx.client;
    d->key = canbus_wire_arb_key(tx.id, tx.flags);
    memcpy(d->data, tx.data, 8);
    w->dup_pending = true;
    w->dup_fault = ref(w, dup);
    return 0;
}

int canbus__fault_close_spells(canbus_wire_t *w, int64_t t_ns)
{
    for (size_t i = 0; i < w->n_faults; i++) {
        int64_t end;
        uint32_t hits;
        if (canbus_fault_spell_over(&w->faults[i], t_ns, &end, &hits) &&
            fault_event(w, &w->faults[i], CANBUS_FAULT_CLEARED, end, w->faults[i].target,
                        CANBUS_ANY_ID, hits))
            return CANBUS_WIRE_ENOMEM;
    }
    return 0;
}
