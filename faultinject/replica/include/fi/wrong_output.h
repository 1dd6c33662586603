/* SPDX-License-Identifier: Apache-2.0 */
/* The arbitrary-value replica: a `wrong_output` fault that makes one replica's output on one
 * axis wrong while the replica otherwise runs as it should.
 *
 *     wrong_output:fid=ID,at=TIME[,until][,period,on],mode=MODE,axis=AXIS[,value=X]
 *                 [,period_osc=TIME][,seed=N]
 *
 *   bias         the axis + value (value required)
 *   random       a value drawn uniformly in the axis's range, anew each time it is applied,
 *                from a generator seeded by `seed` (default 0) and the time: the same run
 *                gives the same values
 *   oscillating  the axis + value * sin(2 pi (t - start of the spell) / period_osc)
 *                (value required; period_osc default 1 s)
 *   hardover     the axis's range limit, upper for value >= 0 (the default), lower below
 *
 * The replica reports what the fault does through a line it prints (REPORT_APPLICATION_MESSAGE
 * in a partition): "fault <fid> wrong_output applied <detail>" when the fault first alters an
 * output in a spell, "fault <fid> wrong_output cleared <detail>" when that spell is over.
 * Pure C11: no allocation, no I/O, no global state. */
#ifndef FI_WRONG_OUTPUT_H
#define FI_WRONG_OUTPUT_H

#include <stddef.h>
#include <stdint.h>

#include "fi/spec.h"

typedef enum {
    FI_WO_BIAS = 0,
    FI_WO_RANDOM = 1,
    FI_WO_OSCILLATING = 2,
    FI_WO_HARDOVER = 3,
} fi_wo_mode_t;

/* An output the fault may act on, as its user names it, and its range. */
typedef struct {
    const char *name;
    double lo, hi;
} fi_wo_axis_t;

/* A parsed fault: what it is and when. */
typedef struct {
    fi_spec_t spec;
    fi_wo_mode_t mode;
    int axis; /* index into the user's axes */
    char axis_name[16];
    double lo, hi; /* the axis's range */
    double value;
    int64_t period_osc_ns;
    uint64_t seed;
} fi_wo_t;

/* Where a fault is in its spells: the user keeps one per fault, zeroed by fi_wo_reset(). */
typedef struct {
    int64_t spell;   /* the spell it acts in, -1: none */
    uint32_t frames; /* outputs it altered in that spell */
} fi_wo_state_t;

#define FI_WO_REPORT_MAX 160 /* a partition's message holds 128: the detail comes last */

/* What a call says to report, in order (at most a `cleared` and an `applied`). */
typedef struct {
    int n;
    char line[2][FI_WO_REPORT_MAX];
} fi_wo_reports_t;

/* Parses `text` for the axes the caller has. 0, or -1 with one line in err. */
int fi_wo_parse(const char *text, const fi_wo_axis_t *axes, int n_axes, fi_wo_t *out, char *err,
                size_t errlen);
void fi_wo_reset(fi_wo_state_t *st);
/* At time t: *x (the axis's value this time, or NULL when there is none) as the fault makes
 * it, and the reports due. */
void fi_wo_apply(const fi_wo_t *f, fi_wo_state_t *st, int64_t t_ns, double *x,
                 fi_wo_reports_t *rep);
/* One line describing the fault, e.g. "mode=bias axis=elev value=0.3". */
void fi_wo_describe(const fi_wo_t *f, char *buf, size_t len);
const char *fi_wo_mode_name(fi_wo_mode_t m);

#endif
