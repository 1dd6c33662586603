/* SPDX-License-Identifier: Apache-2.0 */
/* The arbitrary-value replica (fi/wrong_output.h): parsing, the four modes, the reports. */
#include "fi/wrong_output.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const mode_names[] = {"bias", "random", "oscillating", "hardover"};

const char *fi_wo_mode_name(fi_wo_mode_t m)
{
    return (unsigned)m <= FI_WO_HARDOVER ? mode_names[m] : "?";
}

static int bad(char *err, size_t errlen, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int bad(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

static const char *const known_keys[] = {"mode", "axis", "value", "period_osc", "seed"};

int fi_wo_parse(const char *text, const fi_wo_axis_t *axes, int n_axes, fi_wo_t *out, char *err,
                size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (fi_spec_parse(text, &out->spec, err, errlen))
        return -1;
    const fi_spec_t *s = &out->spec;
    if (strcmp(s->cls, "wrong_output") != 0)
        return bad(err, errlen, "%s: not a wrong_output fault", s->cls);
    for (int i = 0; i < s->n_params; i++) {
        bool known = false;
        for (size_t k = 0; k < sizeof known_keys / sizeof known_keys[0]; k++)
            known |= strcmp(s->params[i].key, known_keys[k]) == 0;
        if (!known)
            return bad(err, errlen, "wrong_output: unknown parameter '%s'", s->params[i].key);
    }
    const char *mode = fi_spec_param(s, "mode");
    int found = -1;
    for (int m = 0; mode && m <= FI_WO_HARDOVER; m++)
        if (strcmp(mode, mode_names[m]) == 0)
            found = m;
    if (found < 0)
        return bad(err, errlen, "wrong_output: mode=bias|random|oscillating|hardover is required");
    out->mode = (fi_wo_mode_t)found;
    const char *axis = fi_spec_param(s, "axis");
    out->axis = -1;
    for (int a = 0; axis && a < n_axes; a++)
        if (strcmp(axis, axes[a].name) == 0)
            out->axis = a;
    if (out->axis < 0)
        return bad(err, errlen, "wrong_output: axis=%s is not one of the outputs",
                   axis ? axis : "(missing)");
    snprintf(out->axis_name, sizeof out->axis_name, "%s", axes[out->axis].name);
    out->lo = axes[out->axis].lo;
    out->hi = axes[out->axis].hi;
    bool need_value = out->mode == FI_WO_BIAS || out->mode == FI_WO_OSCILLATING;
    if (need_value && !fi_spec_param(s, "value"))
        return bad(err, errlen, "wrong_output: mode=%s needs value=X", mode);
    if (fi_spec_double(s, "value", 1.0, &out->value))
        return bad(err, errlen, "wrong_output: value must be a finite number");
    if (fi_spec_time(s, "period_osc", 1000000000, &out->period_osc_ns) || out->period_osc_ns <= 0)
        return bad(err, errlen, "wrong_output: period_osc must be a time > 0");
    const char *seed = fi_spec_param(s, "seed");
    if (seed) {
        char *end;
        errno = 0;
        unsigned long long v = strtoull(seed, &end, 0);
        if (end == seed || *end || errno || *seed == '-')
            return bad(err, errlen, "wrong_output: seed must be a whole number >= 0");
        out->seed = v;
    }
    return 0;
}

void fi_wo_reset(fi_wo_state_t *st)
{
    st->spell = -1;
    st->frames = 0;
}

/* splitmix64's finaliser: a well-mixed 64-bit function of its argument. */
static uint64_t mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* A draw in [0, 1) that depends on the seed and the time only, so that it is the same in
 * every run and after a restart, with no generator state to keep. */
static double draw(uint64_t seed, int64_t t_ns)
{
    uint64_t z = mix(seed * 0x9E3779B97F4A7C15ULL + (uint64_t)t_ns);
    return (double)(z >> 11) * 0x1.0p-53;
}

static double wrong(const fi_wo_t *f, int64_t t_ns, int64_t spell_start, double x)
{
    switch (f->mode) {
    case FI_WO_BIAS: return x + f->value;
    case FI_WO_RANDOM: return f->lo + (f->hi - f->lo) * draw(f->seed, t_ns);
    case FI_WO_OSCILLATING: {
        double phase = (double)(t_ns - spell_start) / (double)f->period_osc_ns;
        return x + f->value * sin(2.0 * M_PI * phase);
    }
    case FI_WO_HARDOVER: return f->value >= 0 ? f->hi : f->lo;
    }
    return x;
}

void fi_wo_describe(const fi_wo_t *f, char *buf, size_t len)
{
    int n = snprintf(buf, len, "mode=%s axis=%s", fi_wo_mode_name(f->mode), f->axis_name);
    if (n < 0 || (size_t)n >= len)
        return;
    switch (f->mode) {
    case FI_WO_BIAS: snprintf(buf + n, len - (size_t)n, " value=%g", f->value); break;
    case FI_WO_RANDOM: snprintf(buf + n, len - (size_t)n, " seed=%" PRIu64, f->seed); break;
    case FI_WO_OSCILLATING:
        snprintf(buf + n, len - (size_t)n, " value=%g period_osc=%gs", f->value,
                 (double)f->period_osc_ns / 1e9);
        break;
    case FI_WO_HARDOVER: snprintf(buf + n, len - (size_t)n, " to=%g", f->value >= 0 ? f->hi : f->lo); break;
    }
}

static void report(const fi_wo_t *f, fi_wo_reports_t *rep, const char *state, const char *detail)
{
    snprintf(rep->line[rep->n++], FI_WO_REPORT_MAX, "fault %s wrong_output %s %s", f->spec.fid,
             state, detail);
}

void fi_wo_apply(const fi_wo_t *f, fi_wo_state_t *st, int64_t t_ns, double *x,
                 fi_wo_reports_t *rep)
{
    rep->n = 0;
    int64_t k = fi_spec_spell(&f->spec, t_ns);
    char what[80];
    if (st->spell >= 0 && k != st->spell) {
        char detail[100];
        fi_wo_describe(f, what, sizeof what);
        snprintf(detail, sizeof detail, "%s frames=%" PRIu32, what, st->frames);
        report(f, rep, "cleared", detail);
        fi_wo_reset(st);
    }
    if (k < 0 || !x)
        return;
    if (st->spell < 0) {
        fi_wo_describe(f, what, sizeof what);
        report(f, rep, "applied", what);
        st->spell = k;
        st->frames = 0;
    }
    st->frames++;
    *x = wrong(f, t_ns, fi_spec_spell_start(&f->spec, k), *x);
}
