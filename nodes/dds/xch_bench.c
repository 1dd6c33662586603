/* SPDX-License-Identifier: Apache-2.0 */
/* ima-xch-bench: one-way latency of the cross-channel exchange through two live DDS agents.
 *
 * Plays the io partitions of two nodes (xch_client, as the real io does), one thread each.
 * Each round, node A sends its INPUTS for frame F (its agent
 * publishes them and waits for node B's); then, after a pause that lets that traffic settle,
 * node B sends its INPUTS for F at t0, and node A's AGREED for F, holding B's inputs, arrives
 * at t1. t1 - t0 is the one-way path io B -> agent B -> DDS -> agent A -> io A; both ends are
 * read on CLOCK_MONOTONIC, one clock for the whole machine, so no clocks need agreeing.
 * Prints one JSON object. */
#include <errno.h>
#include <getopt.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "xch/client.h"

static int64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void sleep_us(long us)
{
    struct timespec ts = {us / 1000000, (us % 1000000) * 1000};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

static int cmp_i64(const void *x, const void *y)
{
    int64_t p = *(const int64_t *)x, q = *(const int64_t *)y;
    return p < q ? -1 : p > q;
}

static double pct_us(const int64_t *v, int n, double p)
{
    int i = (int)(p * n / 100.0 + 0.999999);
    if (i < 1)
        i = 1;
    if (i > n)
        i = n;
    return v[i - 1] / 1000.0;
}

/* One node's side of the bench. */
typedef struct {
    xch_client_t cl;
    int node;
    const char *sock;
} side_t;

static struct {
    side_t side[2];
    long rounds, warmup, gap_us;
    uint32_t wait;
    pthread_barrier_t start, end;
    int64_t *t0, *t1;
    bool *complete, *complete_b; /* per round: A's AGREED held both, B's did */
    atomic_int failed; /* 0, or the first error (negative errno); both sides then stop */
    atomic_long failed_round;
} B;

/* Sends this side's INPUTS of round r (unless the bench already failed). */
static int send_inputs(side_t *s, long r)
{
    if (atomic_load(&B.failed))
        return -ECANCELED;
    struct xch_inputs in;
    memset(&in, 0, sizeof in);
    in.valid = XCH_IN_GPS;
    in.wait_mask = B.wait;
    in.gps_seq = (uint32_t)r;
    in.gps[0] = s->node;
    return xch_client_send(&s->cl, XCH_INPUTS, (uint32_t)r, (int64_t)r * 50000000, &in,
                           sizeof in);
}

static void fail(long r, int rc)
{
    int none = 0;
    if (atomic_compare_exchange_strong(&B.failed, &none, rc))
        atomic_store(&B.failed_round, r);
}

/* Node A: sends first, then waits for the AGREED that B's inputs complete. */
static void *run_a(void *arg)
{
    (void)arg;
    side_t *s = &B.side[0];
    for (long r = 0; r < B.rounds; r++) {
        struct xch_agreed g;
        int rc = send_inputs(s, r);
        pthread_barrier_wait(&B.start);
        if (rc == 0)
            rc = xch_client_await(&s->cl, (uint32_t)r, &g, 10000);
        B.t1[r] = mono_ns();
        if (rc != 0)
            fail(r, rc);
        else
            B.complete[r] = (g.present & B.wait) == B.wait;
        pthread_barrier_wait(&B.end);
        sleep_us(B.gap_us);
    }
    return NULL;
}

/* Node B: sends once A's inputs have settled; its send is t0. */
static void *run_b(void *arg)
{
    (void)arg;
    side_t *s = &B.side[1];
    for (long r = 0; r < B.rounds; r++) {
        struct xch_agreed g;
        pthread_barrier_wait(&B.start);
        sleep_us(B.gap_us);
        B.t0[r] = mono_ns();
        int rc = send_inputs(s, r);
        if (rc == 0)
            rc = xch_client_await(&s->cl, (uint32_t)r, &g, 10000);
        if (rc != 0)
            fail(r, rc);
        else
            B.complete_b[r] = (g.present & B.wait) == B.wait;
        pthread_barrier_wait(&B.end);
    }
    return NULL;
}

int main(int argc, char **argv)
{
    long count = 1000;
    B.side[0] = (side_t){.node = 1};
    B.side[1] = (side_t){.node = 2};
    B.warmup = 50;
    B.gap_us = 1000;
    static const struct option opts[] = {
        {"socket-a", required_argument, NULL, 'a'}, {"socket-b", required_argument, NULL, 'b'},
        {"node-a", required_argument, NULL, 'A'},   {"node-b", required_argument, NULL, 'B'},
        {"count", required_argument, NULL, 'n'},    {"warmup", required_argument, NULL, 'w'},
        {"gap-us", required_argument, NULL, 'g'},   {NULL, 0, NULL, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        switch (c) {
        case 'a': B.side[0].sock = optarg; break;
        case 'b': B.side[1].sock = optarg; break;
        case 'A': B.side[0].node = atoi(optarg); break;
        case 'B': B.side[1].node = atoi(optarg); break;
        case 'n': count = atol(optarg); break;
        case 'w': B.warmup = atol(optarg); break;
        case 'g': B.gap_us = atol(optarg); break;
        default:
            fputs("usage: ima-xch-bench --socket-a PATH --socket-b PATH [--node-a 1] "
                  "[--node-b 2] [--count 1000] [--warmup 50] "
                  "[--gap-us 1000]\n",
                  stderr);
            return 2;
        }
    }
    int na = B.side[0].node, nb = B.side[1].node;
    if (!B.side[0].sock || !B.side[1].sock || count < 1 || B.warmup < 0 || B.gap_us < 0 ||
        na < 1 || nb < 1 || na > XCH_MAX_NODES || nb > XCH_MAX_NODES || na == nb) {
        fputs("ima-xch-bench: --socket-a and --socket-b are required (two different nodes "
              "1..3), --count at least 1\n",
              stderr);
        return 2;
    }
    char err[256];
    for (int i = 0; i < 2; i++)
        if (xch_client_connect(&B.side[i].cl, B.side[i].sock, (unsigned)B.side[i].node, err,
                               sizeof err) != 0) {
            fprintf(stderr, "ima-xch-bench: %s\n", err);
            return 1;
        }
    B.rounds = B.warmup + count;
    B.wait = (1u << (na - 1)) | (1u << (nb - 1));
    B.t0 = calloc((size_t)B.rounds, sizeof *B.t0);
    B.t1 = calloc((size_t)B.rounds, sizeof *B.t1);
    B.complete = calloc((size_t)B.rounds, sizeof *B.complete);
    B.complete_b = calloc((size_t)B.rounds, sizeof *B.complete_b);
    int64_t *lat = malloc((size_t)count * sizeof *lat);
    if (!B.t0 || !B.t1 || !B.complete || !B.complete_b || !lat)
        return 1;
    pthread_barrier_init(&B.start, NULL, 2);
    pthread_barrier_init(&B.end, NULL, 2);
    pthread_t th[2];
    for (int i = 0; i < 2; i++)
        if (pthread_create(&th[i], NULL, i == 0 ? run_a : run_b, NULL) != 0) {
            fputs("ima-xch-bench: cannot start a thread\n", stderr);
            return 1;
        }
    for (int i = 0; i < 2; i++)
        pthread_join(th[i], NULL);
    xch_client_close(&B.side[0].cl);
    xch_client_close(&B.side[1].cl);
    if (atomic_load(&B.failed)) {
        fprintf(stderr, "ima-xch-bench: round %ld: %s\n", atomic_load(&B.failed_round),
                strerror(-atomic_load(&B.failed)));
        return 1;
    }
    long got = 0, incomplete = 0;
    for (long r = 0; r < B.rounds; r++) {
        if (!B.complete[r] || !B.complete_b[r])
            incomplete++;
        else if (r >= B.warmup)
            lat[got++] = B.t1[r] - B.t0[r];
    }
    if (got == 0) {
        fputs("ima-xch-bench: no complete exchange\n", stderr);
        return 1;
    }
    qsort(lat, (size_t)got, sizeof *lat, cmp_i64);
    printf("{\"samples\":%ld,\"incomplete\":%ld,\"min_us\":%.1f,\"median_us\":%.1f,"
           "\"p95_us\":%.1f,\"max_us\":%.1f,\"gap_us\":%ld,"
           "\"measure\":\"one-way io B -> agent B -> DDS -> agent A -> io A, one host's "
           "CLOCK_MONOTONIC\"}\n",
           got, incomplete, lat[0] / 1000.0, pct_us(lat, (int)got, 50), pct_us(lat, (int)got, 95),
           lat[got - 1] / 1000.0, B.gap_us);
    free(lat);
    free(B.t0);
    free(B.t1);
    free(B.complete);
    free(B.complete_b);
    return 0;
}
