/* SPDX-License-Identifier: Apache-2.0 */
/* Which nodes' INPUTS a frame waits for and goes into its AGREED (rules in agent__agree.h). */
#include "agent__agree.h"

#include <string.h>

void agree_init(agree_t *a, unsigned self, unsigned nodes)
{
    memset(a, 0, sizeof *a);
    a->self = self;
    a->nodes = nodes;
}

static agree_peer_t *peer(agree_t *a, unsigned node)
{
    return node >= 1 && node <= a->nodes ? &a->peer[node - 1] : NULL;
}

static const agree_slot_t *find(const agree_t *a, unsigned node, uint32_t frame)
{
    const agree_slot_t *s = &a->peer[node - 1].ring[frame % AGREE_RING];
    return s->used && s->frame == frame ? s : NULL;
}

static bool put(agree_t *a, unsigned node, uint32_t frame, int64_t t_ns,
                const struct xch_inputs *in, bool lost)
{
    agree_peer_t *p = peer(a, node);
    if (!p)
        return false;
    bool own = node == a->self;
    /* Whatever becomes of the sample, the node is publishing again and has reached frame. */
    if (p->withdrawn && !p->resumed) {
        p->resumed = true;
        p->resume_frame = frame;
    }
    if (!p->have_newest || (int32_t)(frame - p->newest) > 0 || own) {
        p->newest = frame;
        p->have_newest = true;
    }
    /* A frame already answered can change nothing; an io that restarts may ask again for an
     * old frame, so this node's own inputs are kept whatever their frame. */
    if (!own && a->answered && (int32_t)(frame - a->last_answered) <= 0) {
        a->stale++;
        return false;
    }
    agree_slot_t *s = &p->ring[frame % AGREE_RING];
    if (!own && s->used && (int32_t)(frame - s->frame) < 0) {
        a->stale++;
        return false;
    }
    /* A frame marked lost stays lost: its late sample must not count for some agents and not
     * for others, depending on when it came. */
    if (!own && s->used && s->frame == frame && s->lost && !lost) {
        a->stale++;
        return false;
    }
    s->used = true;
    s->lost = lost;
    s->frame = frame;
    s->t_ns = t_ns;
    if (lost)
        memset(&s->in, 0, sizeof s->in);
    else
        s->in = *in;
    a->stored++;
    a->lost += lost;
    return true;
}

bool agree_store(agree_t *a, unsigned node, uint32_t frame, int64_t t_ns,
                 const struct xch_inputs *in)
{
    return put(a, node, frame, t_ns, in, false);
}

bool agree_store_lost(agree_t *a, unsigned node, uint32_t frame, int64_t t_ns)
{
    /* A node's own inputs are never lost to itself. */
    return node != a->self && put(a, node, frame, t_ns, NULL, true);
}

/* Withdrawn from frame: neither waited for nor included (agent__agree.h). */
static bool withdrawn_from(const agree_peer_t *p, uint32_t frame)
{
    return p->withdrawn && (!p->resumed || (int32_t)(frame - p->resume_frame) <= 0);
}

uint32_t agree_mask(const agree_t *a, uint32_t wait_mask)
{
    uint32_t all = a->nodes >= 32 ? ~0u : (1u << a->nodes) - 1u;
    return wait_mask & all & ~(1u << (a->self - 1));
}

uint32_t agree_missing(const agree_t *a, uint32_t frame, uint32_t wait_mask)
{
    uint32_t missing = 0;
    uint32_t m = agree_mask(a, wait_mask);
    for (unsigned k = 1; k <= a->nodes; k++) {
        if (!(m & (1u << (k - 1))))
            continue;
        const agree_peer_t *p = &a->peer[k - 1];
        if (p->dead || withdrawn_from(p, frame) || find(a, k, frame))
            continue;
        if (p->have_newest && (int32_t)(p->newest - frame) > 0)
            continue; /* it is past this frame: it will never publish it */
        missing |= 1u << (k - 1);
    }
    return missing;
}

void agree_build(agree_t *a, uint32_t frame, uint32_t wait_mask, struct xch_agreed *out)
{
    memset(out, 0, sizeof *out);
    uint32_t m = agree_mask(a, wait_mask) | (1u << (a->self - 1));
    for (unsigned k = 1; k <= a->nodes; k++) {
        if (!(m & (1u << (k - 1))))
            continue;
        const agree_slot_t *s = find(a, k, frame);
        if (!s || s->lost || (k != a->self && withdrawn_from(&a->peer[k - 1], frame)))
            continue;
        out->present |= 1u << (k - 1);
        out->in[k - 1] = s->in;
    }
    if (!a->answered || (int32_t)(frame - a->last_answered) > 0)
        a->last_answered = frame;
    a->answered = true;
}

void agree_set_dead(agree_t *a, unsigned node)
{
    agree_peer_t *p = peer(a, node);
    if (p)
        p->dead = true;
}

void agree_set_withdrawn(agree_t *a, unsigned node)
{
    agree_peer_t *p = peer(a, node);
    if (p && node != a->self) {
        p->withdrawn = true;
        p->resumed = false;
    }
}
