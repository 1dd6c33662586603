/* SPDX-License-Identifier: Apache-2.0 */
/* Port hashes (ima-ske --trace-port-hashes), for a data-isolation oracle: at the end of each
 * window, one port_hash event per source port its partition wrote in it, with an FNV-1a 64
 * hash of what it wrote. Read from port memory between windows: deterministic. */
#include "ske__supervisor.h"

#include <inttypes.h>
#include <stdio.h>

uint64_t ske_fnv1a64(uint64_t h, const void *data, size_t len)
{
    const uint8_t *b = data;
    for (size_t i = 0; i < len; i++) {
        h ^= b[i];
        h *= 0x100000001b3ULL; /* the 64-bit FNV prime */
    }
    return h;
}

/* What the partition's source ports hold as it gets the CPU. */
void ske__port_hash_grant(ske_t *s, ske_part_t *p)
{
    if (!s->opts.trace_port_hashes)
        return;
    ske_port_hashes_t *h = &s->hashes;
    for (int k = 0; k < p->cfg->n_ports; k++) {
        const ske_port_cfg_t *pc = &p->cfg->ports[k];
        if (pc->dir != SKE_DIR_SOURCE)
            continue;
        int64_t t;
        if (pc->kind == SKE_PORT_SAMPLING && !ske_sampling_latest(p->ports[k].mem, pc->max_size, &h->seq[k], &t))
            h->seq[k] = 0;
        h->qhash[k] = SKE_FNV_OFFSET;
        h->qbytes[k] = 0;
        h->qcount[k] = 0;
    }
}

/* One message a queuing source port sent, as the SKE moves it to its destination. */
void ske__port_hash_queue(ske_t *s, int k, const void *msg, uint32_t len)
{
    if (!s->opts.trace_port_hashes)
        return;
    ske_port_hashes_t *h = &s->hashes;
    h->qhash[k] = ske_fnv1a64(h->qhash[k], msg, len);
    h->qbytes[k] += len;
    h->qcount[k]++;
}

static void trace_hash(ske_t *s, int64_t t, const ske_part_t *p, int k, uint64_t hash,
                       uint64_t len, uint32_t seq)
{
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, hash);
    ske_trace_begin(&s->trace, t, "ske", "port_hash");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_str(&s->trace, "port", p->cfg->ports[k].name);
    ske_trace_str(&s->trace, "hash", hex);
    ske_trace_int(&s->trace, "len", (int64_t)len);
    ske_trace_int(&s->trace, "seq", seq);
}

/* At the window's end: a sampling port whose latest message is not the one it held at the
 * grant was written; a queuing port sent what was moved. */
void ske__port_hash_end(ske_t *s, ske_part_t *p, int64_t t)
{
    if (!s->opts.trace_port_hashes)
        return;
    const ske_port_hashes_t *h = &s->hashes;
    for (int k = 0; k < p->cfg->n_ports; k++) {
        const ske_port_cfg_t *pc = &p->cfg->ports[k];
        if (pc->dir != SKE_DIR_SOURCE)
            continue;
        if (pc->kind == SKE_PORT_SAMPLING) {
            uint32_t len, seq;
            const void *msg = ske_sampling_latest_msg(p->ports[k].mem, pc->max_size, &len, &seq);
            if (!msg || seq == h->seq[k])
                continue;
            trace_hash(s, t, p, k, ske_fnv1a64(SKE_FNV_OFFSET, msg, len), len, seq);
            ske_trace_end(&s->trace);
        } else if (h->qcount[k] > 0) {
            const ske_queue_hdr_t *q = p->ports[k].mem;
            trace_hash(s, t, p, k, h->qhash[k], h->qbytes[k], atomic_load(&q->tail));
            ske_trace_int(&s->trace, "messages", h->qcount[k]);
            ske_trace_end(&s->trace);
        }
    }
}
