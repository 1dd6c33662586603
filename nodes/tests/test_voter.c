/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the redundancy voter: the truth table of one frame against a naive oracle,
 * mid-value select, persistence, degradation, disagreement, reset, configuration, determinism. */
#include "voter/voter.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "canbus_test.h"

/* Same bits (so +0 and -0, or two NaNs, are told apart or not exactly). */
#define CHECK_BITS(a, e)                                                                      \
    do {                                                                                      \
        double a_ = (a), e_ = (e);                                                            \
        if (memcmp(&a_, &e_, sizeof a_) != 0) {                                               \
            fprintf(stderr, "%s:%d: %s is %s: got %a, expected %a\n", __FILE__, __LINE__, #a, \
                    #e, a_, e_);                                                              \
            unit_failures++;                                                                  \
        }                                                                                     \
    } while (0)

#define DIM 4

static voter_cfg_t make_cfg(unsigned n, unsigned persist)
{
    voter_cfg_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.n = n;
    cfg.dim = DIM;
    cfg.persist = persist;
    for (unsigned d = 0; d < DIM; d++) {
        cfg.threshold[d] = 0.1;
        cfg.safe[d] = -0.5 - d; /* distinct from every value the tests vote on */
    }
    return cfg;
}

static void init(voter_t *v, unsigned n, unsigned persist)
{
    voter_cfg_t cfg = make_cfg(n, persist);
    CHECK_EQ(voter_init(v, &cfg), 0);
}

static const double healthy[DIM] = {0.5, -0.25, 0.0, 0.75};

/* Every channel's vector set to the healthy one. */
static void fill_healthy(double x[VOTER_MAX_CH][VOTER_MAX_DIM])
{
    memset(x, 0, sizeof(double) * VOTER_MAX_CH * VOTER_MAX_DIM);
    for (unsigned c = 0; c < VOTER_MAX_CH; c++)
        memcpy(x[c], healthy, sizeof healthy);
}

static voter_out_t step(voter_t *v, double x[VOTER_MAX_CH][VOTER_MAX_DIM], uint8_t present)
{
    voter_out_t out;
    memset(&out, 0xA5, sizeof out); /* the voter must write every byte we look at */
    voter_step(v, (const double(*)[VOTER_MAX_DIM])x, present, &out);
    return out;
}

static unsigned popcount3(uint8_t m)
{
    return (m & 1u) + ((m >> 1) & 1u) + ((m >> 2) & 1u);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* --- the truth table --------------------------------------------------------------------- */

/* One frame of the rules, written the obvious way (sorting for the median), from a voter in
 * which the channels of `failed` are failed and every other count is 0. */
struct expect {
    double value[DIM];
    voter_status_t status;
    uint8_t used, miscompare, newly_failed, failed;
    uint8_t reason[VOTER_MAX_CH];
    unsigned count[VOTER_MAX_CH];
    bool newly_disagree;
};

static struct expect oracle(unsigned n, unsigned persist, uint8_t present, uint8_t failed,
                            double x[VOTER_MAX_CH][VOTER_MAX_DIM])
{
    struct expect e;
    memset(&e, 0, sizeof e);
    uint8_t all = (uint8_t)((1u << n) - 1u);
    uint8_t cand = present & all & (uint8_t)~failed;
    unsigned k = popcount3(cand), idx[3], j = 0;
    for (unsigned c = 0; c < n; c++)
        if (cand & (1u << c))
            idx[j++] = c;
    voter_cfg_t cfg = make_cfg(n, persist);

    e.status = k == 3 ? VOTER_MID3 : k == 2 ? VOTER_AVG2 : k == 1 ? VOTER_SINGLE : VOTER_SAFE;
    e.used = cand;
    for (unsigned d = 0; d < DIM; d++) {
        if (k == 3) {
            double s[3] = {x[idx[0]][d], x[idx[1]][d], x[idx[2]][d]};
            qsort(s, 3, sizeof s[0], cmp_double);
            e.value[d] = s[1];
        } else if (k == 2) {
            e.value[d] = (x[idx[0]][d] + x[idx[1]][d]) / 2;
        } else if (k == 1) {
            e.value[d] = x[idx[0]][d];
        } else {
            e.value[d] = cfg.safe[d];
        }
    }
    bool pair_bad = false;
    for (unsigned i = 0; k == 2 && i < 2; i++)
        for (unsigned d = 0; d < DIM; d++)
            if (fabs(x[idx[i]][d] - e.value[d]) > cfg.threshold[d])
                pair_bad = true;
    e.failed = failed;
    for (unsigned c = 0; c < n; c++) {
        uint8_t bit = (uint8_t)(1u << c);
        if (failed & bit) {
            e.reason[c] = VOTER_REASON_ABSENT; /* how the test failed them */
            continue;
        }
        voter_reason_t why = VOTER_REASON_NONE;
        if (!(present & bit)) {
            why = VOTER_REASON_ABSENT;
        } else if (k == 3) {
            for (unsigned d = 0; d < DIM; d++)
                if (fabs(x[c][d] - e.value[d]) > cfg.threshold[d])
                    why = VOTER_REASON_MISCOMPARE;
        } else if (pair_bad) {
            e.miscompare |= bit; /* the pair's fault, not the channel's */
        }
        if (why != VOTER_REASON_NONE) {
            e.miscompare |= bit;
            e.count[c] = 1;
            if (persist == 1) {
                e.newly_failed |= bit;
                e.failed |= bit;
                e.reason[c] = (uint8_t)why;
            }
        }
    }
    if (pair_bad && persist == 1) {
        e.status = VOTER_DISAGREE;
        e.newly_disagree = true;
        e.used = 0;
        for (unsigned d = 0; d < DIM; d++)
            e.value[d] = cfg.safe[d];
    }
    return e;
}

/* Values of a channel that "miscompares": pattern 0 moves every such channel on the elevator
 * (by different amounts, so two of them outvote a healthy one), pattern 1 moves channel c on
 * component c only (so every per-component median is healthy). */
static void apply_bias(double x[VOTER_MAX_CH][VOTER_MAX_DIM], uint8_t mis, int pattern)
{
    for (unsigned c = 0; c < VOTER_MAX_CH; c++) {
        if (!(mis & (1u << c)))
            continue;
        if (pattern == 0)
            x[c][0] += 0.5 * (c + 1);
        else
            x[c][c] -= 0.3 * (c + 1);
    }
}

static void test_truth_table(void)
{
    unsigned cases = 0;
    for (unsigned n = 1; n <= 3; n++)
        for (unsigned persist = 1; persist <= 3; persist += 2)
            for (unsigned failed_in = 0; failed_in < 8; failed_in++)
                for (unsigned present = 0; present < 8; present++)
                    for (unsigned mis = 0; mis < 8; mis++)
                        for (int pattern = 0; pattern < 2; pattern++) {
                            uint8_t all = (uint8_t)((1u << n) - 1u);
                            uint8_t failed = (uint8_t)failed_in & all;
                            voter_t v;
                            double x[VOTER_MAX_CH][VOTER_MAX_DIM];
                            init(&v, n, persist);
                            fill_healthy(x);
                            /* Fail the channels of `failed` by absence. */
                            for (unsigned f = 0; f < persist; f++) {
                                voter_out_t o = step(&v, x, all & (uint8_t)~failed);
                                CHECK_EQ(o.newly_failed, f + 1 == persist ? failed : 0);
                            }
                            CHECK_EQ(v.failed, failed);
                            apply_bias(x, (uint8_t)mis, pattern);
                            struct expect e = oracle(n, persist, (uint8_t)present, failed, x);
                            voter_out_t o = step(&v, x, (uint8_t)present);
                            int before = unit_failures;
                            for (unsigned d = 0; d < DIM; d++)
                                CHECK_BITS(o.value[d], e.value[d]);
                            for (unsigned d = DIM; d < VOTER_MAX_DIM; d++)
                                CHECK_BITS(o.value[d], 0.0);
                            CHECK_EQ(o.status, e.status);
                            CHECK_EQ(o.used, e.used);
                            CHECK_EQ(o.miscompare, e.miscompare);
                            CHECK_EQ(o.newly_failed, e.newly_failed);
                            CHECK_EQ(o.newly_disagree, e.newly_disagree);
                            CHECK_EQ(v.failed, e.failed);
                            CHECK_EQ(v.disagree, e.newly_disagree);
                            for (unsigned c = 0; c < n; c++) {
                                CHECK_EQ(v.reason[c], e.reason[c]);
                                if (!(e.failed & (1u << c)))
                                    CHECK_EQ(v.count[c], e.count[c]);
                            }
                            if (unit_failures != before)
                                fprintf(stderr, "  in case n=%u persist=%u failed=%u "
                                        "present=%u miscompare=%u pattern=%d\n",
                                        n, persist, failed, present, mis, pattern);
                            cases++;
                        }
    CHECK_EQ(cases, 3 * 2 * 8 * 8 * 8 * 2);
}

/* --- mid-value select ----------------------------------------------------------------------- */

static void check_mid3_all_orders(double a, double b, double c, double want)
{
    double p[6][3] = {{a, b, c}, {a, c, b}, {b, a, c}, {b, c, a}, {c, a, b}, {c, b, a}};
    for (int i = 0; i < 6; i++)
        CHECK_BITS(voter_mid3(p[i][0], p[i][1], p[i][2]), want);
}

static void test_mid3(void)
{
    check_mid3_all_orders(1.0, 2.0, 3.0, 2.0);
    check_mid3_all_orders(-3.0, -1.0, -2.0, -2.0);
    check_mid3_all_orders(-0.75, 0.25, 1e300, 0.25);
    check_mid3_all_orders(1.0, 1.0, 2.0, 1.0);
    check_mid3_all_orders(1.0, 2.0, 2.0, 2.0);
    check_mid3_all_orders(-5.0, -5.0, -5.0, -5.0);
    check_mid3_all_orders(-INFINITY, 0.5, INFINITY, 0.5);
    check_mid3_all_orders(INFINITY, INFINITY, 1.0, INFINITY);
    check_mid3_all_orders(-INFINITY, -INFINITY, 7.0, -INFINITY);
    check_mid3_all_orders(-INFINITY, INFINITY, INFINITY, INFINITY);
    check_mid3_all_orders(DBL_TRUE_MIN, 0.0, 1.0, DBL_TRUE_MIN);
    check_mid3_all_orders(-DBL_MAX, DBL_MAX, -DBL_TRUE_MIN, -DBL_TRUE_MIN);
    check_mid3_all_orders(-0.0, -0.0, -0.0, -0.0);
    check_mid3_all_orders(0.0, 0.0, 0.0, 0.0);
    /* +0 and -0 compare equal: the result is a zero, always the same one for the same order. */
    double z[3] = {0.0, -0.0, 1.0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) {
                if (i == j || j == k || i == k)
                    continue;
                double r1 = voter_mid3(z[i], z[j], z[k]), r2 = voter_mid3(z[i], z[j], z[k]);
                CHECK(r1 == 0.0);
                CHECK_BITS(r1, r2);
            }
    CHECK(voter_mid3(-0.0, 0.0, -1.0) == 0.0);
    /* NaN: never chosen over a number; one NaN gives the smaller of the other two. */
    check_mid3_all_orders(NAN, 1.0, 2.0, 1.0);
    check_mid3_all_orders(NAN, -2.0, 2.0, -2.0);
    check_mid3_all_orders(NAN, INFINITY, -INFINITY, -INFINITY);
    check_mid3_all_orders(NAN, NAN, 3.0, 3.0);
    check_mid3_all_orders(NAN, NAN, -INFINITY, -INFINITY);
    CHECK(isnan(voter_mid3(NAN, NAN, NAN)));
}

/* --- the voted value -------------------------------------------------------------------------- */

static void test_values(void)
{
    voter_t v;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    voter_out_t o;

    /* Average of two, exactly (a + b) / 2, per component. */
    init(&v, 2, 3);
    fill_healthy(x);
    x[0][0] = 0.25;
    x[1][0] = 0.3; /* within 0.1 of the average */
    x[0][3] = -1.0 / 3.0;
    x[1][3] = -0.3;
    o = step(&v, x, 0x3);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK_EQ(o.used, 0x3);
    CHECK_EQ(o.miscompare, 0);
    CHECK_BITS(o.value[0], (0.25 + 0.3) / 2);
    CHECK_BITS(o.value[1], -0.25);
    CHECK_BITS(o.value[3], (-1.0 / 3.0 + -0.3) / 2);

    /* Three: the median per component, from different channels if need be. */
    init(&v, 3, 3);
    fill_healthy(x);
    x[0][0] = 0.51, x[1][0] = 0.52, x[2][0] = 0.53;
    x[0][1] = -0.2, x[1][1] = -0.3, x[2][1] = -0.25;
    x[0][2] = -0.0, x[1][2] = -0.0, x[2][2] = 0.05;
    o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_MID3);
    CHECK_EQ(o.used, 0x7);
    CHECK_BITS(o.value[0], 0.52);
    CHECK_BITS(o.value[1], -0.25);
    CHECK_BITS(o.value[2], -0.0);
    CHECK_BITS(o.value[3], 0.75);
    CHECK_EQ(o.miscompare, 0);

    /* Three with B absent: the average of A and C; one: that channel, bit for bit. */
    o = step(&v, x, 0x5);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK_EQ(o.used, 0x5);
    CHECK_BITS(o.value[0], (0.51 + 0.53) / 2);
    o = step(&v, x, 0x2);
    CHECK_EQ(o.status, VOTER_SINGLE);
    CHECK_EQ(o.used, 0x2);
    for (unsigned d = 0; d < DIM; d++)
        CHECK_BITS(o.value[d], x[1][d]);

    /* None: the safe state. */
    init(&v, 3, 3);
    o = step(&v, NULL, 0);
    CHECK_EQ(o.status, VOTER_SAFE);
    CHECK_EQ(o.used, 0);
    CHECK_EQ(o.miscompare, 0x7);
    for (unsigned d = 0; d < DIM; d++)
        CHECK_BITS(o.value[d], -0.5 - d);

    /* Bits of channels beyond n are ignored. */
    init(&v, 2, 1);
    fill_healthy(x);
    x[2][0] = 100.0;
    o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK_EQ(o.used, 0x3);
    CHECK_EQ(o.newly_failed, 0);
    CHECK_BITS(o.value[0], 0.5);

    /* Infinities: one infinite replica out of three is outvoted and miscompares. */
    init(&v, 3, 1);
    fill_healthy(x);
    x[1][2] = INFINITY;
    o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_MID3);
    CHECK_BITS(o.value[2], 0.0);
    CHECK_EQ(o.miscompare, 0x2);
    CHECK_EQ(o.newly_failed, 0x2);
    CHECK_EQ(v.reason[1], VOTER_REASON_MISCOMPARE);
    /* Two equal infinities out of three are the median and do not miscompare. */
    init(&v, 3, 1);
    fill_healthy(x);
    x[0][2] = x[2][2] = -INFINITY;
    o = step(&v, x, 0x7);
    CHECK_BITS(o.value[2], -INFINITY);
    CHECK_EQ(o.miscompare, 0x2);
    /* A pair at +inf and -inf averages to NaN: a disagreement. */
    init(&v, 2, 2);
    fill_healthy(x);
    x[0][1] = INFINITY;
    x[1][1] = -INFINITY;
    o = step(&v, x, 0x3);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK(isnan(o.value[1]));
    CHECK_EQ(o.miscompare, 0x3);
    CHECK_EQ(v.disagree_count, 1);

    /* A NaN: not a candidate, counts as a miscompare, fails the channel at persist. */
    init(&v, 3, 2);
    fill_healthy(x);
    x[2][3] = NAN;
    o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK_EQ(o.used, 0x3);
    CHECK_EQ(o.miscompare, 0x4);
    CHECK_BITS(o.value[3], 0.75);
    CHECK_EQ(o.newly_failed, 0);
    o = step(&v, x, 0x7);
    CHECK_EQ(o.newly_failed, 0x4);
    CHECK_EQ(v.reason[2], VOTER_REASON_MISCOMPARE);
}

/* --- persistence, degradation, disagreement --------------------------------------------------- */

static void test_persistence(void)
{
    voter_t v;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    voter_out_t o;

    /* persist - 1 bad frames then a clean one: the count starts again. */
    init(&v, 3, 3);
    fill_healthy(x);
    x[1][0] += 0.2;
    for (int i = 0; i < 2; i++) {
        o = step(&v, x, 0x7);
        CHECK_EQ(o.miscompare, 0x2);
        CHECK_EQ(o.newly_failed, 0);
    }
    CHECK_EQ(v.count[1], 2);
    fill_healthy(x);
    o = step(&v, x, 0x7);
    CHECK_EQ(o.miscompare, 0);
    CHECK_EQ(v.count[1], 0);
    x[1][0] += 0.2;
    for (int i = 0; i < 2; i++)
        CHECK_EQ(step(&v, x, 0x7).newly_failed, 0);
    /* The persist-th consecutive one latches, reported once. */
    o = step(&v, x, 0x7);
    CHECK_EQ(o.newly_failed, 0x2);
    CHECK_EQ(o.status, VOTER_MID3);
    CHECK_BITS(o.value[0], 0.5);
    CHECK_EQ(v.failed, 0x2);
    CHECK_EQ(v.reason[1], VOTER_REASON_MISCOMPARE);
    fill_healthy(x); /* healthy again: still failed */
    o = step(&v, x, 0x7);
    CHECK_EQ(o.newly_failed, 0);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK_EQ(o.used, 0x5);
    CHECK_EQ(v.failed, 0x2);

    /* Absence: the same count, reason absent; a frame present breaks the run. */
    init(&v, 3, 3);
    fill_healthy(x);
    step(&v, x, 0x3);
    step(&v, x, 0x3);
    step(&v, x, 0x7);
    CHECK_EQ(v.count[2], 0);
    step(&v, x, 0x3);
    step(&v, x, 0x3);
    o = step(&v, x, 0x3);
    CHECK_EQ(o.newly_failed, 0x4);
    CHECK_EQ(v.reason[2], VOTER_REASON_ABSENT);
    CHECK_EQ(step(&v, x, 0x3).newly_failed, 0);

    /* Misses and miscompares add up; the reason is that of the frame that reached persist. */
    init(&v, 3, 3);
    fill_healthy(x);
    step(&v, x, 0x6);
    step(&v, x, 0x6);
    x[0][3] -= 0.5;
    o = step(&v, x, 0x7);
    CHECK_EQ(o.newly_failed, 0x1);
    CHECK_EQ(v.reason[0], VOTER_REASON_MISCOMPARE);
    init(&v, 3, 3);
    step(&v, x, 0x7);
    step(&v, x, 0x7);
    o = step(&v, x, 0x6);
    CHECK_EQ(o.newly_failed, 0x1);
    CHECK_EQ(v.reason[0], VOTER_REASON_ABSENT);

    /* With one candidate nothing can miscompare, whatever its values. */
    init(&v, 3, 1);
    fill_healthy(x);
    x[1][0] = 1e9;
    o = step(&v, x, 0x2);
    CHECK_EQ(o.status, VOTER_SINGLE);
    CHECK_EQ(o.miscompare, 0x5);
    CHECK_EQ(o.newly_failed, 0x5);
    CHECK_EQ(v.failed, 0x5);
    CHECK_EQ(v.count[1], 0);
}

static void test_degradation(void)
{
    voter_t v;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    voter_out_t o;
    init(&v, 3, 3);
    fill_healthy(x);
    CHECK_EQ(step(&v, x, 0x7).status, VOTER_MID3);
    /* C stops: averaged at once, failed at its third miss. */
    for (int i = 1; i <= 3; i++) {
        o = step(&v, x, 0x3);
        CHECK_EQ(o.status, VOTER_AVG2);
        CHECK_EQ(o.used, 0x3);
        CHECK_EQ(o.newly_failed, i == 3 ? 0x4 : 0);
    }
    /* C speaks again: it stays out. */
    o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_AVG2);
    CHECK_EQ(o.used, 0x3);
    /* B stops: A alone. */
    for (int i = 1; i <= 3; i++) {
        o = step(&v, x, 0x1);
        CHECK_EQ(o.status, VOTER_SINGLE);
        CHECK_EQ(o.used, 0x1);
        CHECK_EQ(o.newly_failed, i == 3 ? 0x2 : 0);
        CHECK_EQ(v.reason[1], i == 3 ? VOTER_REASON_ABSENT : VOTER_REASON_NONE);
    }
    for (unsigned d = 0; d < DIM; d++)
        CHECK_BITS(o.value[d], healthy[d]);
    /* A stops: the safe state at once, A failed at its third miss. */
    for (int i = 1; i <= 3; i++) {
        o = step(&v, x, 0);
        CHECK_EQ(o.status, VOTER_SAFE);
        CHECK_EQ(o.used, 0);
        CHECK_EQ(o.newly_failed, i == 3 ? 0x1 : 0);
        CHECK_BITS(o.value[0], -0.5);
    }
    CHECK_EQ(v.failed, 0x7);
    /* Everybody back: nobody is trusted any more. */
    o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_SAFE);
    CHECK_EQ(o.miscompare, 0);
    CHECK_EQ(v.frames, 12);
}

static void test_disagreement(void)
{
    voter_t v;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    voter_out_t o;
    init(&v, 3, 3);
    fill_healthy(x);
    for (int i = 0; i < 3; i++)
        step(&v, x, 0x3); /* C failed by absence */
    CHECK_EQ(v.failed, 0x4);
    x[1][0] += 0.3; /* A and B 0.3 apart: each 0.15 from the average */
    /* Two disagreements, a clean frame: the pair's count starts again. */
    for (int i = 0; i < 2; i++) {
        o = step(&v, x, 0x3);
        CHECK_EQ(o.status, VOTER_AVG2);
        CHECK_EQ(o.miscompare, 0x3);
        CHECK_BITS(o.value[0], (0.5 + 0.8) / 2);
        CHECK_EQ(o.newly_disagree, 0);
    }
    CHECK_EQ(v.disagree_count, 2);
    CHECK_EQ(v.count[0], 0); /* the channels are not blamed */
    CHECK_EQ(v.count[1], 0);
    o = step(&v, x, 0x1); /* B missing once: one candidate, not a disagreement */
    CHECK_EQ(o.status, VOTER_SINGLE);
    CHECK_EQ(v.disagree_count, 0);
    CHECK_EQ(v.count[1], 1);
    for (int i = 1; i <= 3; i++) {
        o = step(&v, x, 0x3);
        CHECK_EQ(o.newly_failed, 0);
        CHECK_EQ(o.newly_disagree, i == 3);
        CHECK_EQ(o.status, i == 3 ? VOTER_DISAGREE : VOTER_AVG2);
        CHECK_EQ(o.used, i == 3 ? 0 : 0x3);
    }
    CHECK_EQ(v.count[1], 0);
    for (unsigned d = 0; d < DIM; d++)
        CHECK_BITS(o.value[d], -0.5 - d);
    CHECK(v.disagree);
    CHECK_EQ(v.failed, 0x4);
    /* Latched: agreeing again changes nothing, reported once. */
    fill_healthy(x);
    o = step(&v, x, 0x3);
    CHECK_EQ(o.status, VOTER_DISAGREE);
    CHECK_EQ(o.newly_disagree, 0);
    CHECK_EQ(o.used, 0);
    CHECK_EQ(o.miscompare, 0);
    CHECK_BITS(o.value[0], -0.5);
    /* Misses are still counted. */
    for (int i = 1; i <= 3; i++)
        o = step(&v, x, 0x1);
    CHECK_EQ(o.status, VOTER_DISAGREE);
    CHECK_EQ(o.newly_failed, 0x2);
    CHECK_EQ(v.reason[1], VOTER_REASON_ABSENT);

    /* A configured pair (n = 2) disagrees the same way; persist 1 declares at once. */
    init(&v, 2, 1);
    fill_healthy(x);
    x[0][2] = 0.5;
    o = step(&v, x, 0x3);
    CHECK_EQ(o.status, VOTER_DISAGREE);
    CHECK(o.newly_disagree);
    CHECK_EQ(o.newly_failed, 0);
    CHECK_EQ(v.failed, 0);
}

static void test_reset(void)
{
    voter_t v, fresh;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    voter_cfg_t cfg = make_cfg(3, 2);
    cfg.threshold[2] = 0.7;
    CHECK_EQ(voter_init(&v, &cfg), 0);
    CHECK_EQ(voter_init(&fresh, &cfg), 0);
    fill_healthy(x);
    step(&v, x, 0x1);
    step(&v, x, 0x1); /* B and C failed */
    x[0][0] = 1.0;
    step(&v, x, 0x1);
    CHECK_EQ(v.failed, 0x6);
    voter_reset(&v);
    CHECK(memcmp(&v, &fresh, sizeof v) == 0);
    CHECK_BITS(v.cfg.threshold[2], 0.7);
    fill_healthy(x);
    voter_out_t o = step(&v, x, 0x7);
    CHECK_EQ(o.status, VOTER_MID3);
    CHECK_EQ(v.frames, 1);

    /* Reset also ends a latched disagreement. */
    CHECK_EQ(voter_init(&v, &(voter_cfg_t){.n = 2, .dim = 1, .persist = 1, .threshold = {0}}),
             0);
    x[1][0] = 0.6;
    CHECK_EQ(step(&v, x, 0x3).status, VOTER_DISAGREE);
    voter_reset(&v);
    CHECK(!v.disagree);
    CHECK_EQ(v.disagree_count, 0);
    fill_healthy(x);
    CHECK_EQ(step(&v, x, 0x3).status, VOTER_AVG2);
}

static void test_init(void)
{
    voter_t v, before;
    voter_cfg_t good = make_cfg(3, 3), bad;
    memset(&before, 0x5A, sizeof before);

#define REJECTS(edit)                                                                         \
    do {                                                                                      \
        bad = good;                                                                           \
        edit;                                                                                 \
        v = before;                                                                           \
        CHECK_EQ(voter_init(&v, &bad), -1);                                                   \
        CHECK(memcmp(&v, &before, sizeof v) == 0);                                            \
    } while (0)
    REJECTS(bad.n = 0);
    REJECTS(bad.n = VOTER_MAX_CH + 1);
    REJECTS(bad.dim = 0);
    REJECTS(bad.dim = VOTER_MAX_DIM + 1);
    REJECTS(bad.persist = 0);
    REJECTS(bad.threshold[0] = -0.1);
    REJECTS(bad.threshold[DIM - 1] = -INFINITY);
    REJECTS(bad.threshold[1] = NAN);
    REJECTS(bad.threshold[1] = -NAN);
#undef REJECTS
    CHECK_EQ(voter_init(NULL, &good), -1);
    CHECK_EQ(voter_init(&v, NULL), -1);

    /* The edges that are fine; thresholds beyond dim are not looked at. */
    bad = good;
    bad.threshold[0] = 0.0;
    bad.threshold[1] = INFINITY;
    bad.threshold[DIM] = NAN;
    bad.threshold[VOTER_MAX_DIM - 1] = -1.0;
    CHECK_EQ(voter_init(&v, &bad), 0);
    CHECK_EQ(v.failed, 0);
    CHECK_EQ(v.frames, 0);
    bad = good;
    bad.n = 1;
    bad.dim = VOTER_MAX_DIM;
    bad.persist = 1;
    for (unsigned d = 0; d < VOTER_MAX_DIM; d++)
        bad.threshold[d] = 0.5;
    CHECK_EQ(voter_init(&v, &bad), 0);
    CHECK(memcmp(&v.cfg, &bad, sizeof bad) == 0);
}

static void test_thresholds_per_component(void)
{
    voter_t v;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    voter_cfg_t cfg = make_cfg(3, 1);
    const double thr[DIM] = {0.125, 0.25, 0.5, 1.0};
    memcpy(cfg.threshold, thr, sizeof thr);
    for (unsigned d = 0; d < DIM; d++) {
        /* Exactly at the threshold: clean (the rule is "more than"). */
        CHECK_EQ(voter_init(&v, &cfg), 0);
        memset(x, 0, sizeof x);
        x[2][d] = thr[d];
        voter_out_t o = step(&v, x, 0x7);
        CHECK_EQ(o.miscompare, 0);
        /* Just above, on this component only: a miscompare. */
        CHECK_EQ(voter_init(&v, &cfg), 0);
        x[2][d] = nextafter(thr[d], 2.0);
        o = step(&v, x, 0x7);
        CHECK_EQ(o.miscompare, 0x4);
        CHECK_EQ(o.newly_failed, 0x4);
        /* A deviation that is fine for the next component is not for this one (when the
         * thresholds grow), and the other way round. */
        if (d + 1 < DIM) {
            CHECK_EQ(voter_init(&v, &cfg), 0);
            memset(x, 0, sizeof x);
            x[0][d + 1] = thr[d + 1];
            x[0][d] = thr[d] * 0.5;
            CHECK_EQ(step(&v, x, 0x7).miscompare, 0);
            CHECK_EQ(voter_init(&v, &cfg), 0);
            memset(x, 0, sizeof x);
            x[0][d] = thr[d + 1];
            CHECK_EQ(step(&v, x, 0x7).miscompare, 0x1);
        }
    }
}

/* --- determinism ------------------------------------------------------------------------------ */

static uint64_t rng_state;

static uint64_t rng(void)
{
    /* splitmix64 */
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Healthy replicas (a common value plus small noise), with biases that come and go and
 * channels that miss frames: enough to go through every status. */
static void run_sequence(uint64_t seed, voter_t *v, voter_out_t *outs, unsigned frames)
{
    double x[VOTER_MAX_CH][VOTER_MAX_DIM];
    bool biased[VOTER_MAX_CH] = {false, false, false};
    rng_state = seed;
    for (unsigned f = 0; f < frames; f++) {
        uint8_t present = 0;
        for (unsigned c = 0; c < VOTER_MAX_CH; c++) {
            if (rng() % 20 == 0)
                biased[c] = !biased[c];
            if (rng() % 8 != 0)
                present |= (uint8_t)(1u << c);
        }
        for (unsigned d = 0; d < VOTER_MAX_DIM; d++) {
            double common = (double)(int64_t)(rng() % 2001 - 1000) / 2000.0;
            for (unsigned c = 0; c < VOTER_MAX_CH; c++)
                x[c][d] = common + (double)(int64_t)(rng() % 101 - 50) / 1000.0 +
                          (biased[c] && d == c ? 0.8 : 0.0);
        }
        voter_step(v, (const double(*)[VOTER_MAX_DIM])x, present, &outs[f]);
        if (f % 97 == 96)
            voter_reset(v);
    }
}

static void test_determinism(void)
{
    enum { FRAMES = 2000 };
    static voter_out_t a[FRAMES], b[FRAMES];
    voter_t va, vb;
    voter_cfg_t cfg = make_cfg(3, 3);
    cfg.dim = VOTER_MAX_DIM;
    for (unsigned d = 0; d < VOTER_MAX_DIM; d++)
        cfg.threshold[d] = 0.3;
    memset(a, 0x11, sizeof a);
    memset(b, 0x22, sizeof b);
    CHECK_EQ(voter_init(&va, &cfg), 0);
    CHECK_EQ(voter_init(&vb, &cfg), 0);
    run_sequence(42, &va, a, FRAMES);
    run_sequence(42, &vb, b, FRAMES);
    CHECK(memcmp(a, b, sizeof a) == 0);
    CHECK(memcmp(&va, &vb, sizeof va) == 0);
    /* And the sequence is not trivial: every status shows up. */
    unsigned seen = 0;
    for (unsigned f = 0; f < FRAMES; f++)
        seen |= 1u << a[f].status;
    CHECK_EQ(seen, 0x1F);
}

static void test_names(void)
{
    CHECK(strcmp(voter_status_name(VOTER_MID3), "MID3") == 0);
    CHECK(strcmp(voter_status_name(VOTER_AVG2), "AVG2") == 0);
    CHECK(strcmp(voter_status_name(VOTER_SINGLE), "SINGLE") == 0);
    CHECK(strcmp(voter_status_name(VOTER_SAFE), "SAFE") == 0);
    CHECK(strcmp(voter_status_name(VOTER_DISAGREE), "DISAGREE") == 0);
    CHECK(strcmp(voter_status_name((voter_status_t)99), "?") == 0);
    CHECK(strcmp(voter_reason_name(VOTER_REASON_NONE), "none") == 0);
    CHECK(strcmp(voter_reason_name(VOTER_REASON_MISCOMPARE), "miscompare") == 0);
    CHECK(strcmp(voter_reason_name(VOTER_REASON_ABSENT), "absent") == 0);
    CHECK(strcmp(voter_reason_name((voter_reason_t)7), "?") == 0);
    CHECK_EQ(voter_sizeof_cfg(), sizeof(voter_cfg_t));
    CHECK_EQ(voter_sizeof_voter(), sizeof(voter_t));
    CHECK_EQ(voter_sizeof_out(), sizeof(voter_out_t));
}

int main(void)
{
    test_truth_table();
    test_mid3();
    test_values();
    test_persistence();
    test_degradation();
    test_disagreement();
    test_reset();
    test_init();
    test_thresholds_per_component();
    test_determinism();
    test_names();
    if (unit_failures) {
        fprintf(stderr, "test_voter: %d check(s) failed\n", unit_failures);
        return 1;
    }
    printf("test_voter: ok\n");
    return 0;
}
