/* SPDX-License-Identifier: Apache-2.0 */
/* The spells of a bus fault in bus time, which frames it hits, and when its trace says it
 * applied and cleared: pure functions of the fault and the time. */
#include "canbus__fault.h"

int64_t canbus_fault_spell(const canbus_fault_t *f, int64_t t_ns)
{
    if (t_ns < f->from_ns || t_ns >= f->until_ns)
        return -1;
    if (f->period_ns <= 0)
        return 0;
    int64_t k = (t_ns - f->from_ns) / f->period_ns;
    return t_ns - f->from_ns - k * f->period_ns < f->on_ns ? k : -1;
}

int64_t canbus_fault_spell_end(const canbus_fault_t *f, int64_t k)
{
    if (f->period_ns <= 0)
        return f->until_ns;
    int64_t end = f->from_ns + k * f->period_ns + f->on_ns;
    return end < f->until_ns ? end : f->until_ns;
}

int64_t canbus_fault_next_edge(const canbus_fault_t *f, int64_t t_ns)
{
    if (t_ns < f->from_ns)
        return f->from_ns;
    if (t_ns >= f->until_ns)
        return INT64_MAX;
    if (f->period_ns <= 0)
        return f->until_ns;
    int64_t k = (t_ns - f->from_ns) / f->period_ns;
    int64_t start = f->from_ns + k * f->period_ns;
    int64_t next = t_ns < start + f->on_ns ? start + f->on_ns : start + f->period_ns;
    return next < f->until_ns ? next : f->until_ns;
}

bool canbus_fault_matches(const canbus_fault_t *f, uint8_t client, uint32_t id, int64_t t_ns)
{
    if (f->limit && f->used >= f->limit)
        return false;
    if (f->target == CANBUS_NOBODY || (f->target != CANBUS_ANY && f->target != client))
        return false;
    if (f->match_id != CANBUS_ANY_ID && f->match_id != id)
        return false;
    return canbus_fault_spell(f, t_ns) >= 0;
}

canbus_fault_t *canbus_fault_find(canbus_fault_t *v, size_t n, uint8_t kind, uint8_t client,
                                  uint32_t id, int64_t t_ns)
{
    for (size_t i = 0; i < n; i++)
        if (v[i].kind == kind && canbus_fault_matches(&v[i], client, id, t_ns))
            return &v[i];
    return NULL;
}

canbus_fault_note_t canbus_fault_hit(canbus_fault_t *f, int64_t t_ns)
{
    canbus_fault_note_t n = {0};
    int64_t k = canbus_fault_spell(f, t_ns);
    if (k < 0 || k <= f->last_spell) {
        /* A frame matched in a spell whose events are written already (it waited for the
         * wire past the spell's end): counted, no new event. */
        if (k >= 0 && k == f->spell)
            f->spell_hits++;
        return n;
    }
    if (f->spell >= 0) {
        /* The spell it acted in is over and its end was not seen yet (no wire time between). */
        n.cleared = true;
        n.cleared_spell = f->spell;
        n.cleared_hits = f->spell_hits;
    }
    n.applied = true;
    f->spell = f->last_spell = k;
    f->spell_hits = 1;
    return n;
}

bool canbus_fault_spell_over(canbus_fault_t *f, int64_t t_ns, int64_t *end_ns, uint32_t *hits)
{
    if (f->spell < 0)
        return false;
    int64_t end = canbus_fault_spell_end(f, f->spell);
    if (end > t_ns)
        return false;
    *end_ns = end;
    *hits = f->spell_hits;
    f->spell = -1;
    return true;
}
