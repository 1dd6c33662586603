/* SPDX-License-Identifier: Apache-2.0 */
/* The cyclic plan of a module as a sequence of window activations in module time. */
#include "ske/plan.h"

/* A schedule's windows in m->windows. A module built by hand (no schedules) is one. */
static void range(const ske_module_cfg_t *m, int schedule, int *first, int *n)
{
    if (m->n_schedules == 0 || schedule < 0 || schedule >= m->n_schedules) {
        *first = 0;
        *n = m->n_windows;
        return;
    }
    *first = m->schedules[schedule].first_window;
    *n = m->schedules[schedule].n_windows;
}

static void fill(const ske_module_cfg_t *m, ske_slot_t *s)
{
    int first, n;
    range(m, s->schedule, &first, &n);
    (void)n;
    s->window = &m->windows[first + s->index];
    s->start_ns = s->frame * m->major_frame_ns + s->window->offset_ns;
    s->end_ns = s->start_ns + s->window->duration_ns;
}

void ske_plan_first(const ske_module_cfg_t *m, ske_slot_t *slot)
{
    slot->frame = 0;
    slot->schedule = m->n_schedules ? m->initial_schedule : 0;
    slot->index = 0;
    fill(m, slot);
}

void ske_plan_next(const ske_module_cfg_t *m, ske_slot_t *slot)
{
    int first, n;
    range(m, slot->schedule, &first, &n);
    (void)first;
    if (++slot->index >= n) {
        slot->index = 0;
        slot->frame++;
    }
    fill(m, slot);
}

void ske_plan_switch(const ske_module_cfg_t *m, ske_slot_t *slot, int schedule)
{
    slot->schedule = schedule;
    slot->index = 0;
    fill(m, slot);
}

void ske_plan_at(const ske_module_cfg_t *m, int64_t t, ske_slot_t *slot)
{
    int first, n;
    slot->schedule = m->n_schedules ? m->initial_schedule : 0;
    range(m, slot->schedule, &first, &n);
    if (t < 0)
        t = 0;
    slot->frame = t / m->major_frame_ns;
    int64_t off = t % m->major_frame_ns;
    for (int i = 0; i < n; i++) {
        const ske_window_cfg_t *w = &m->windows[first + i];
        if (off < w->offset_ns + w->duration_ns) {
            slot->index = i;
            fill(m, slot);
            return;
        }
    }
    slot->frame++;
    slot->index = 0;
    fill(m, slot);
}

int64_t ske_plan_partition_ns_in(const ske_module_cfg_t *m, int schedule, int pi)
{
    int first, n;
    range(m, schedule, &first, &n);
    int64_t sum = 0;
    for (int i = first; i < first + n; i++)
        if (m->windows[i].partition == pi)
            sum += m->windows[i].duration_ns;
    return sum;
}

int64_t ske_plan_partition_ns(const ske_module_cfg_t *m, int pi)
{
    return ske_plan_partition_ns_in(m, m->n_schedules ? m->initial_schedule : 0, pi);
}

int64_t ske_plan_idle_ns(const ske_module_cfg_t *m)
{
    int first, n;
    range(m, m->n_schedules ? m->initial_schedule : 0, &first, &n);
    int64_t sum = 0;
    for (int i = first; i < first + n; i++)
        sum += m->windows[i].duration_ns;
    return m->major_frame_ns - sum;
}
