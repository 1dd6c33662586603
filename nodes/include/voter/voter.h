/* SPDX-License-Identifier: Apache-2.0 */
/* The redundancy voter: one C library for every place in the product that votes over the
 * replicas of a value (the smart actuators over the flight-control replicas' commands, each
 * node's io partition over the cross-channel inputs and its own output). Pure computation, no
 * I/O, no allocation, no clock: the caller says when a voting frame happens.
 *
 * A voter has n channels (replicas, 1..VOTER_MAX_CH) of a vector of dim values
 * (1..VOTER_MAX_DIM). Once per voting frame the caller gives each channel's vector and a mask
 * of the channels that delivered one this frame (present). The voter then:
 *
 *   1. Candidates = channels that are present and not failed (failure is latched), in
 *      channel order (and without a NaN, see below).
 *   2. Votes each component over the candidates:
 *        3 candidates: mid-value select (the median of the three);
 *        2 candidates: the average of the two;
 *        1 candidate:  that channel's value;
 *        0 candidates: cfg.safe[d] (the safe state), status VOTER_SAFE.
 *   3. Monitors every channel that is not failed:
 *        - present and |x[c][d] - voted[d]| > cfg.threshold[d] for some d: a miscompare;
 *        - absent: a miss.
 *      Either one increments the channel's consecutive count, a clean frame resets it to 0.
 *      A channel whose count reaches cfg.persist is declared failed (latched until
 *      voter_reset(); reported once in voter_out_t.newly_failed with the reason: that of the
 *      frame that reached the count).
 *      With 3 candidates the median cannot miscompare with itself, so a single wrong replica
 *      is isolated. With 2 candidates a miscompare shows as both differing from their average
 *      by more than the threshold: neither can be blamed, so the pair is declared in
 *      disagreement (VOTER_DISAGREE, latched) after cfg.persist consecutive frames; from that
 *      frame on the output is the safe state (fail-passive, no channel used), until
 *      voter_reset(); misses are still counted. A channel that goes absent while two are
 *      left is still blamed for its misses (3 -> 2 -> 1 by loss works).
 *      With 1 candidate there is nothing to compare against: no miscompare can be declared.
 *   4. The status says how the value was formed (enum voter_status).
 *
 * Same inputs in the same order give the same outputs, bit for bit (no floating-point
 * reordering beyond the documented formulae: median by comparisons, average (a + b) / 2).
 * A present channel with a NaN in its vector is not a candidate that frame and counts a
 * miscompare. With 2 candidates the channels' own counts are not incremented for a
 * miscompare (only the pair's disagreement count is; the channels' counts go back to 0, they
 * delivered); misses always count. Which pair disagrees: either member differs from the
 * average by more than the threshold on some component (an infinity of each sign averages to
 * NaN: a disagreement). */
#ifndef VOTER_VOTER_H
#define VOTER_VOTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define VOTER_MAX_CH 3
#define VOTER_MAX_DIM 12

typedef enum voter_status {
    VOTER_MID3 = 0,     /* three candidates, median */
    VOTER_AVG2 = 1,     /* two candidates, average */
    VOTER_SINGLE = 2,   /* one candidate */
    VOTER_SAFE = 3,     /* none: the safe state */
    VOTER_DISAGREE = 4, /* two candidates in persistent disagreement: the safe state, latched */
} voter_status_t;

typedef enum voter_reason {
    VOTER_REASON_NONE = 0,
    VOTER_REASON_MISCOMPARE = 1, /* differed from the voted value by more than the threshold */
    VOTER_REASON_ABSENT = 2,     /* delivered nothing for persist consecutive frames */
} voter_reason_t;

typedef struct voter_cfg {
    unsigned n;                       /* channels, 1..VOTER_MAX_CH */
    unsigned dim;                     /* components per vector, 1..VOTER_MAX_DIM */
    double threshold[VOTER_MAX_DIM];  /* per component, >= 0 */
    unsigned persist;                 /* consecutive bad frames before failing a channel, >= 1 */
    double safe[VOTER_MAX_DIM];       /* output with no candidate */
} voter_cfg_t;

typedef struct voter {
    voter_cfg_t cfg;
    unsigned count[VOTER_MAX_CH];     /* consecutive miscompares or misses */
    uint8_t failed;                   /* bit c: channel c failed (latched) */
    uint8_t reason[VOTER_MAX_CH];     /* enum voter_reason of each failed channel */
    unsigned disagree_count;          /* consecutive two-candidate disagreements */
    bool disagree;                    /* VOTER_DISAGREE latched */
    uint64_t frames;                  /* voting frames so far */
} voter_t;

typedef struct voter_out {
    double value[VOTER_MAX_DIM];
    voter_status_t status;
    uint8_t used;         /* bit c: channel c's value formed the output this frame */
    uint8_t miscompare;   /* bit c: channel c miscompared or missed this frame */
    uint8_t newly_failed; /* bit c: channel c was declared failed this frame */
    bool newly_disagree;  /* VOTER_DISAGREE was declared this frame */
} voter_out_t;

/* 0, or -1 if cfg is out of range (n, dim, persist, a negative or NaN threshold). */
int voter_init(voter_t *v, const voter_cfg_t *cfg);
/* Back to no channel failed, counters cleared; the configuration is kept. */
void voter_reset(voter_t *v);
/* One voting frame. x[c] is read only for channels whose bit is set in `present` (bits of
 * channels >= cfg.n are ignored). out is written whole (value[d] = 0 for d >= cfg.dim). */
void voter_step(voter_t *v, const double x[][VOTER_MAX_DIM], uint8_t present, voter_out_t *out);

/* Stateless helpers (also what voter_step uses). */
/* The median. A NaN is never chosen over a number: with one NaN, the smaller of the other two;
 * with two, the number; with three, a. Equal values (+0 and -0 compare equal): which one is
 * returned depends only on the argument order. */
double voter_mid3(double a, double b, double c);
const char *voter_status_name(voter_status_t s); /* "MID3", "AVG2", "SINGLE", "SAFE", "DISAGREE" */
const char *voter_reason_name(voter_reason_t r); /* "none", "miscompare", "absent" */

/* For bindings (sim/imaworld/voter.py mirrors the structs with ctypes and checks its layout
 * against these): sizeof(voter_cfg_t), sizeof(voter_t), sizeof(voter_out_t). */
size_t voter_sizeof_cfg(void);
size_t voter_sizeof_voter(void);
size_t voter_sizeof_out(void);

#endif
