/* SPDX-License-Identifier: Apache-2.0 */
/* Operating modes and module schedules: the SKE's mode events, a partition's
 * SET_PARTITION_MODE (idle, restart) and SET_MODULE_SCHEDULE requests, and the switch of
 * schedule at a major frame. */
#include "ske__supervisor.h"

#include <stdio.h>

const char *ske__mode_name(uint32_t m)
{
    static const char *names[] = {"IDLE", "COLD_START", "WARM_START", "NORMAL"};
    return m < 4 ? names[m] : "?";
}

void ske__trace_mode(ske_t *s, ske_part_t *p, int64_t t, uint32_t mode, uint32_t from,
                     const char *why)
{
    /* The SKE's own record of a mode change it made (power-on, IDLE, restart). */
    ske_trace_begin(&s->trace, t, "ske", "mode");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_str(&s->trace, "mode", ske__mode_name(mode));
    ske_trace_str(&s->trace, "from", ske__mode_name(from));
    if (why)
        ske_trace_str(&s->trace, "reason", why);
    ske_trace_end(&s->trace);
}

/* A partition asked for IDLE or a restart through SET_PARTITION_MODE. */
int ske__handle_mode_request(ske_t *s, ske_part_t *p, int64_t t, char *err, size_t errlen)
{
    uint32_t seq = atomic_load(&p->ctl->mode_request_seq);
    if (seq == p->mode_request_seq)
        return SKE_OK;
    p->mode_request_seq = seq;
    uint32_t req = atomic_load(&p->ctl->mode_request);
    uint32_t cur = atomic_load(&p->ctl->mode);
    if (req == SKE_MODE_IDLE) {
        ske__kill_partition(p);
        p->state = SKE_PS_IDLE;
        ske__trace_mode(s, p, t, SKE_MODE_IDLE, cur, "SET_PARTITION_MODE");
        return SKE_OK;
    }
    if (req == SKE_MODE_COLD_START || req == SKE_MODE_WARM_START) {
        ske__kill_partition(p);
        ske__trace_mode(s, p, t, req, cur, "SET_PARTITION_MODE");
        p->start_condition = 1; /* PARTITION_RESTART */
        p->initial_mode = req;
        p->restarts++;
        p->state = SKE_PS_NOT_STARTED;
        return ske__respawn(s, p, t);
    }
    (void)err;
    (void)errlen;
    return SKE_OK;
}

/* A partition asked for another module schedule (SET_MODULE_SCHEDULE): checked again here,
 * it takes effect at the next major frame (ARINC 653 Part 2, 3.2). */
void ske__take_schedule_request(ske_t *s, ske_part_t *p, int64_t t)
{
    ske_ctl_t *c = p->ctl;
    uint32_t seq = atomic_load(&c->schedule_request_seq);
    if (seq == atomic_load(&c->schedule_request_ack))
        return;
    atomic_store(&c->schedule_request_ack, seq);
    int32_t id = atomic_load(&c->schedule_request);
    const ske_module_cfg_t *m = s->cfg;
    int to = -1;
    for (int i = 0; i < m->n_schedules; i++)
        if (m->schedules[i].id == id)
            to = i;
    if (to < 0 || !p->cfg->schedule_change)
        return; /* the partition's APEX already refused it */
    s->next_schedule = to;
    ske_trace_begin(&s->trace, t, "ske", "schedule_request");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_int(&s->trace, "schedule", id);
    ske_trace_str(&s->trace, "name", m->schedules[to].name);
    ske_trace_end(&s->trace);
    for (int i = 0; i < m->n_partitions; i++)
        if (s->parts[i].ctl)
            atomic_store(&s->parts[i].ctl->next_schedule, id);
}

/* Runs schedule `to` from the frame starting at t: every partition's control block follows. */
void ske__switch_schedule(ske_t *s, ske_slot_t *slot, int to)
{
    const ske_module_cfg_t *m = s->cfg;
    int from = slot->schedule;
    ske_plan_switch(m, slot, to);
    s->last_switch_ns = slot->frame * m->major_frame_ns;
    ske_trace_begin(&s->trace, s->last_switch_ns, "ske", "schedule_switch");
    ske_trace_int(&s->trace, "from", m->schedules[from].id);
    ske_trace_int(&s->trace, "to", m->schedules[to].id);
    ske_trace_str(&s->trace, "name", m->schedules[to].name);
    ske_trace_int(&s->trace, "frame", slot->frame);
    ske_trace_end(&s->trace);
    for (int i = 0; i < m->n_partitions; i++) {
        ske_ctl_t *c = s->parts[i].ctl;
        if (!c)
            continue;
        atomic_store(&c->current_schedule, m->schedules[to].id);
        atomic_store(&c->next_schedule, m->schedules[to].id);
        atomic_store(&c->last_switch_ns, s->last_switch_ns);
        c->duration_ns = m->partitions[i].duration_in[to];
        c->period_anchor_ns = m->partitions[i].anchor_in[to];
    }
}
