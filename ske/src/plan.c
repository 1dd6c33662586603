/* SPDX-License-Identifier: Apache-2.0 */
/* The cyclic plan of a module as a sequence of window activations in module time. */
#include "ske/plan.h"

static void fill(const ske_module_cfg_t *m, ske_slot_t *s)
{
    s->window = &m->windows[s->index];
    s->start_ns = s->frame * m->major_frame_ns + s->window->offset_ns;
    s->end_ns = s->start_ns + s->window->duration_ns;
}

void ske_plan_first(const ske_module_cfg_t *m, ske_slot_t *slot)
{
    slot->frame = 0;
    slot->index = 0;
    fill(m, slot);
}

void ske_plan_next(const ske_module_cfg_t *m, ske_slot_t *slot)
{
    if (++slot->index >= m->n_windows) {
        slot->index = 0;
        slot->frame++;
    }
    fill(m, slot);
}

void ske_plan_at(const ske_module_cfg_t *m, int64_t t, ske_slot_t *slot)
{
    if (t < 0)
        t = 0;
    slot->frame = t / m->major_frame_ns;
    int64_t off = t % m->major_frame_ns;
    for (int i = 0; i < m->n_windows; i++) {
        if (off < m->windows[i].offset_ns + m->windows[i].duration_ns) {
            slot->index = i;
            fill(m, slot);
            return;
        }
    }
    slot->frame++;
    slot->index = 0;
    fill(m, slot);
}

int64_t ske_plan_partition_ns(const ske_module_cfg_t *m, int pi)
{
    int64_t sum = 0;
    for (int i = 0; i < m->n_windows; i++)
        if (m->windows[i].partition == pi)
            sum += m->windows[i].duration_ns;
    return sum;
}

int64_t ske_plan_idle_ns(const ske_module_cfg_t *m)
{
    int64_t sum = 0;
    for (int i = 0; i < m->n_windows; i++)
        sum += m->windows[i].duration_ns;
    return m->major_frame_ns - sum;
}
