/* SPDX-License-Identifier: Apache-2.0 */
/* The DDS agent's faults acting on this node's publications (agent__fault.h decides, frame by
 * frame): samples withheld or held back and published late, the lost marks that keep the
 * emulated-time agreement going without them, and the `fault` trace events. */
#include <inttypes.h>
#include <string.h>

#include "agent__agent.h"

/* The `fault` line of one event: stamped with the fault's emulated time (the wall clock, as
 * every line of this trace, besides) and the frame it was seen at. */
static void trace_note(agent_t *a, const dds_fault_note_t *n, uint32_t frame)
{
    const dds_fault_t *f = &a->faults.f[n->fault];
    if (!agent_trace_begin_at(a, "fault", n->t_ns))
        return;
    fprintf(a->trace,
            ",\"fid\":\"%s\",\"class\":\"%s\",\"target\":\"%s/dds\",\"state\":\"%s\",\"frame\":%" PRIu32,
            f->spec.fid, dds_fault_class(f), a->node_name, n->applied ? "applied" : "cleared",
            frame);
    if (!n->applied)
        fprintf(a->trace, ",\"detail\":\"spell ended after %" PRIu32 " frame(s)\"", n->frames);
    else if (f->kind == DDS_FAULT_DROP)
        fprintf(a->trace, ",\"detail\":\"inputs and health from frame %" PRIu32 " not published%s\"",
                frame, a->o.realtime ? "" : " (marked lost)");
    else
        fprintf(a->trace,
                ",\"detail\":\"inputs and health from frame %" PRIu32 " published %" PRIu32
                " frame(s) late%s\"",
                frame, f->frames, a->o.realtime ? "" : " (marked lost meanwhile)");
    agent_trace_end(a);
}

/* Publishes, in order, what dds_delay held back for io's frames up to `frame`. */
static void release_held(agent_t *a, uint32_t frame)
{
    while (a->held_n) {
        agent_held_t *x = &a->held[a->held_head];
        if ((int32_t)(frame - x->release) < 0)
            return;
        agent_dds_publish(a, x->topic, &x->h, &x->p);
        a->published_late++;
        a->held_head = (a->held_head + 1) % AGENT_HELD_MAX;
        a->held_n--;
    }
}

static void hold(agent_t *a, int topic, const struct xch_hdr *h, const void *payload,
                 uint32_t release)
{
    if (a->held_n == AGENT_HELD_MAX) {
        a->withheld++; /* cannot happen within DDS_DELAY_MAX_FRAMES; lost rather than blocked */
        return;
    }
    agent_held_t *x = &a->held[(a->held_head + a->held_n) % AGENT_HELD_MAX];
    memset(x, 0, sizeof *x);
    x->topic = topic;
    x->release = release;
    x->h = *h;
    if (topic == T_INPUTS)
        x->p.in = *(const struct xch_inputs *)payload;
    else
        x->p.health = *(const struct xch_health *)payload;
    a->held_n++;
}

int agent_fault_publish(agent_t *a, int topic, const struct xch_hdr *h, const void *payload)
{
    if (!a->faults.n)
        return agent_dds_publish(a, topic, h, payload);
    release_held(a, h->frame);
    dds_fault_note_t notes[2 * DDS_FAULT_MAX];
    size_t n_notes;
    uint32_t delay;
    int action = dds_fault_frame(&a->faults, h->frame, h->t_ns, &delay, notes, &n_notes);
    for (size_t i = 0; i < n_notes; i++)
        trace_note(a, &notes[i], h->frame);
    if (action == DDS_PUBLISH)
        return agent_dds_publish(a, topic, h, payload);
    if (action == DDS_DELAY)
        hold(a, topic, h, payload, h->frame + delay);
    else
        a->withheld++;
    if (topic == T_INPUTS && !a->o.realtime) {
        /* In emulated time the others wait for this frame without a time limit: tell them it
         * is lost (agent__agree.h), as their time-out would in real time. */
        struct xch_inputs mark;
        memset(&mark, 0, sizeof mark);
        mark.wait_mask = AGREE_LOST_MARK;
        return agent_dds_publish(a, T_INPUTS, h, &mark);
    }
    return 0;
}
