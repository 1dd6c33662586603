/* SPDX-License-Identifier: Apache-2.0 */
/* The redundancy voter (include/voter/voter.h): mid-value select, monitoring, degradation. */
#include "voter/voter.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* The mask of the channels a voter has. */
static uint8_t all_channels(const voter_t *v)
{
    return (uint8_t)((1u << v->cfg.n) - 1u);
}

/* Median of three numbers by comparisons only: max(min(a, b), min(max(a, b), c)). Equal
 * values (+0 and -0 compare equal) make it return one of them by argument position, always
 * the same one for the same arguments. */
static double median3(double a, double b, double c)
{
    if (a > b) {
        double t = a;
        a = b;
        b = t;
    }
    /* a <= b */
    if (b > c)
        b = c;
    if (a > b)
        b = a;
    return b;
}

double voter_mid3(double a, double b, double c)
{
    int na = isnan(a), nb = isnan(b), nc = isnan(c);
    int nans = na + nb + nc;

    if (nans == 0)
        return median3(a, b, c);
    if (nans == 3)
        return a;
    if (nans == 2)
        return !na ? a : !nb ? b : c;
    /* One NaN: the smaller of the two numbers (the later one when they compare equal), so the
     * result does not depend on where the NaN was. */
    double x = na ? b : a, y = nc ? b : c;
    return x < y ? x : y;
}

/* Whether x miscompares with the voted value v at threshold thr. Written so that a NaN
 * difference counts as a miscompare and equal infinities do not. */
static bool differs(double x, double v, double thr)
{
    if (x == v)
        return false;
    return !(fabs(x - v) <= thr);
}

static bool has_nan(const double *x, unsigned dim)
{
    for (unsigned d = 0; d < dim; d++)
        if (isnan(x[d]))
            return true;
    return false;
}

int voter_init(voter_t *v, const voter_cfg_t *cfg)
{
    if (v == NULL || cfg == NULL)
        return -1;
    if (cfg->n < 1 || cfg->n > VOTER_MAX_CH || cfg->dim < 1 || cfg->dim > VOTER_MAX_DIM ||
        cfg->persist < 1)
        return -1;
    for (unsigned d = 0; d < cfg->dim; d++)
        if (!(cfg->threshold[d] >= 0.0)) /* negative or NaN */
            return -1;
    memset(v, 0, sizeof *v);
    memcpy(&v->cfg, cfg, sizeof *cfg);
    return 0;
}

void voter_reset(voter_t *v)
{
    /* Everything after the configuration, padding included (a reset voter is byte-equal to a
     * fresh one). */
    size_t keep = offsetof(voter_t, count);
    memset((char *)v + keep, 0, sizeof *v - keep);
}

/* Counts one bad frame (a miss or a miscompare) of channel c; fails it at cfg.persist. */
static void count_bad(voter_t *v, unsigned c, voter_reason_t why, voter_out_t *out)
{
    uint8_t bit = (uint8_t)(1u << c);

    out->miscompare |= bit;
    if (v->count[c] < v->cfg.persist)
        v->count[c]++;
    if (v->count[c] >= v->cfg.persist) {
        v->failed |= bit;
        v->reason[c] = (uint8_t)why;
        out->newly_failed |= bit;
    }
}

void voter_step(voter_t *v, const double x[][VOTER_MAX_DIM], uint8_t present, voter_out_t *out)
{
    const unsigned n = v->cfg.n, dim = v->cfg.dim;
    unsigned cand[VOTER_MAX_CH];
    unsigned k = 0;
    uint8_t nan_ch = 0;

    memset(out, 0, sizeof *out);
    present &= all_channels(v);
    v->frames++;

    /* 1. Candidates: present, not failed, no NaN. Channel order, always. */
    for (unsigned c = 0; c < n; c++) {
        uint8_t bit = (uint8_t)(1u << c);
        if (!(present & bit) || (v->failed & bit))
            continue;
        if (has_nan(x[c], dim)) {
            nan_ch |= bit;
            continue;
        }
        cand[k++] = c;
    }

    /* 2. The vote. A latched disagreement overrides it: the safe state, nobody used. */
    if (v->disagree) {
        k = 0;
        out->status = VOTER_DISAGREE;
    } else {
        static const voter_status_t by_count[] = {VOTER_SAFE, VOTER_SINGLE, VOTER_AVG2,
                                                  VOTER_MID3};
        out->status = by_count[k];
    }
    for (unsigned d = 0; d < dim; d++) {
        switch (k) {
        case 3: out->value[d] = median3(x[cand[0]][d], x[cand[1]][d], x[cand[2]][d]); break;
        case 2: out->value[d] = (x[cand[0]][d] + x[cand[1]][d]) / 2.0; break;
        case 1: out->value[d] = x[cand[0]][d]; break;
        default: out->value[d] = v->cfg.safe[d]; break;
        }
    }
    for (unsigned i = 0; i < k; i++)
        out->used |= (uint8_t)(1u << cand[i]);

    /* 3. Monitoring of every channel not failed. */
    bool pair_disagrees = false;
    if (k == 2) {
        for (unsigned i = 0; i < 2 && !pair_disagrees; i++)
            for (unsigned d = 0; d < dim; d++)
                if (differs(x[cand[i]][d], out->value[d], v->cfg.threshold[d])) {
                    pair_disagrees = true;
                    break;
                }
    }
    for (unsigned c = 0; c < n; c++) {
        uint8_t bit = (uint8_t)(1u << c);
        if (v->failed & bit)
            continue;
        if (!(present & bit)) {
            count_bad(v, c, VOTER_REASON_ABSENT, out);
        } else if (nan_ch & bit) {
            count_bad(v, c, VOTER_REASON_MISCOMPARE, out);
        } else if (k == 3) {
            bool bad = false;
            for (unsigned d = 0; d < dim && !bad; d++)
                bad = differs(x[c][d], out->value[d], v->cfg.threshold[d]);
            if (bad)
                count_bad(v, c, VOTER_REASON_MISCOMPARE, out);
            else
                v->count[c] = 0;
        } else if (pair_disagrees) {
            /* Neither of the pair can be blamed: only the pair's count moves. The channel did
             * deliver, so a run of misses is broken. */
            out->miscompare |= bit;
            v->count[c] = 0;
        } else {
            /* One candidate, a clean pair, or present during a latched disagreement. */
            v->count[c] = 0;
        }
    }

    if (pair_disagrees) {
        if (v->disagree_count < v->cfg.persist)
            v->disagree_count++;
        if (v->disagree_count >= v->cfg.persist) {
            /* Declared: this frame's output is already the safe state. */
            v->disagree = true;
            out->newly_disagree = true;
            out->status = VOTER_DISAGREE;
            out->used = 0;
            for (unsigned d = 0; d < dim; d++)
                out->value[d] = v->cfg.safe[d];
        }
    } else if (!v->disagree) {
        v->disagree_count = 0;
    }
}

const char *voter_status_name(voter_status_t s)
{
    switch (s) {
    case VOTER_MID3: return "MID3";
    case VOTER_AVG2: return "AVG2";
    case VOTER_SINGLE: return "SINGLE";
    case VOTER_SAFE: return "SAFE";
    case VOTER_DISAGREE: return "DISAGREE";
    }
    return "?";
}

const char *voter_reason_name(voter_reason_t r)
{
    switch (r) {
    case VOTER_REASON_NONE: return "none";
    case VOTER_REASON_MISCOMPARE: return "miscompare";
    case VOTER_REASON_ABSENT: return "absent";
    }
    return "?";
}

size_t voter_sizeof_cfg(void)
{
    return sizeof(voter_cfg_t);
}

size_t voter_sizeof_voter(void)
{
    return sizeof(voter_t);
}

size_t voter_sizeof_out(void)
{
    return sizeof(voter_out_t);
}
