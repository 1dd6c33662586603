/* SPDX-License-Identifier: Apache-2.0 */
/* The DDS agent's faults (agent__fault.h): parsing, and their decision for each frame. */
#include "agent__fault.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *dds_fault_class(const dds_fault_t *f)
{
    return f->kind == DDS_FAULT_DELAY ? "dds_delay" : "dds_drop";
}

int dds_fault_add(dds_faults_t *set, const char *text, char *err, size_t errlen)
{
    if (set->n == DDS_FAULT_MAX) {
        snprintf(err, errlen, "more than %d faults", DDS_FAULT_MAX);
        return -1;
    }
    dds_fault_t *f = &set->f[set->n];
    memset(f, 0, sizeof *f);
    if (fi_spec_parse(text, &f->spec, err, errlen))
        return -1;
    if (!strcmp(f->spec.cls, "dds_drop")) {
        f->kind = DDS_FAULT_DROP;
    } else if (!strcmp(f->spec.cls, "dds_delay")) {
        f->kind = DDS_FAULT_DELAY;
    } else {
        snprintf(err, errlen, "%s: the DDS agent injects dds_drop and dds_delay", f->spec.cls);
        return -1;
    }
    for (int i = 0; i < f->spec.n_params; i++)
        if (f->kind != DDS_FAULT_DELAY || strcmp(f->spec.params[i].key, "frames")) {
            snprintf(err, errlen, "%s: unknown parameter '%s'", f->spec.cls, f->spec.params[i].key);
            return -1;
        }
    if (f->kind == DDS_FAULT_DELAY) {
        const char *v = fi_spec_param(&f->spec, "frames");
        char *end = NULL;
        errno = 0;
        long n = v ? strtol(v, &end, 10) : 0;
        if (!v || end == v || *end || errno || n < 1 || n > DDS_DELAY_MAX_FRAMES) {
            snprintf(err, errlen, "dds_delay needs frames=N, 1..%d", DDS_DELAY_MAX_FRAMES);
            return -1;
        }
        f->frames = (uint32_t)n;
    }
    for (size_t k = 0; k < set->n; k++)
        if (!strcmp(set->f[k].spec.fid, f->spec.fid)) {
            snprintf(err, errlen, "fault id %s given twice", f->spec.fid);
            return -1;
        }
    f->spell = f->last_spell = -1;
    set->n++;
    return 0;
}

int dds_fault_frame(dds_faults_t *set, uint32_t frame, int64_t t_ns, uint32_t *delay_frames,
                    dds_fault_note_t *notes, size_t *n_notes)
{
    *n_notes = 0;
    if (set->have_frame && set->frame == frame) {
        *delay_frames = set->delay_frames;
        return set->action;
    }
    int action = DDS_PUBLISH;
    uint32_t delay = 0;
    for (size_t i = 0; i < set->n; i++) {
        dds_fault_t *f = &set->f[i];
        int64_t k = fi_spec_spell(&f->spec, t_ns);
        if (f->spell >= 0 && k != f->spell) {
            int64_t end = fi_spec_spell_start(&f->spec, f->spell) + f->spec.on_ns;
            if (f->spec.duration != FI_INTERMITTENT || end > f->spec.until_ns)
                end = f->spec.until_ns;
            notes[(*n_notes)++] = (dds_fault_note_t){.fault = i, .applied = false, .t_ns = end,
                                                     .frames = f->spell_frames};
            f->spell = -1;
        }
        if (k < 0)
            continue;
        if (k > f->last_spell) {
            notes[(*n_notes)++] = (dds_fault_note_t){.fault = i, .applied = true, .t_ns = t_ns};
            f->spell = f->last_spell = k;
            f->spell_frames = 0;
        }
        if (f->spell == k) {
            f->spell_frames++;
            f->total_frames++;
        }
        /* A drop wins over a delay; of two delays, the longer. */
        if (f->kind == DDS_FAULT_DROP)
            action = DDS_WITHHOLD;
        else if (action != DDS_WITHHOLD) {
            action = DDS_DELAY;
            delay = f->frames > delay ? f->frames : delay;
        }
    }
    set->have_frame = true;
    set->frame = frame;
    set->action = action;
    set->delay_frames = delay;
    *delay_frames = delay;
    return action;
}
