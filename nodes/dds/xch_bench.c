/* SPDX-License-Identifier: Apache-2.0 */
/* ima-xch-bench: one-way latency of the cross-channel exchange through two live DDS agents.
 *
 * Plays the io partitions of two nodes (xch_client, as the real io does). Each round, node A
 * sends its INPUTS for frame F (its agent publishes them and waits for node B's), then, after a
 * pause that lets that traffic settle, node B sends its INPUTS for F at t0 and node A's
 * AGREED for F, holding B's inputs, arrives at t1. t1 - t0 is the one-way path io B ->
 * agent B -> DDS -> agent A -> io A, both ends read on this process's CLOCK_MONOTONIC, so no
 * clocks need agreeing. Prints one JSON object. */
#include <errno.h>
#include <getopt.h>
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

int main(int argc, char **argv)
{
    const char *sock[2] = {NULL, NULL};
    int node[2] = {1, 2};
    long count = 1000, warmup = 50, gap_us = 1000;
    static const struct option opts[] = {
        {"socket-a", required_argument, NULL, 'a'}, {"socket-b", required_argument, NULL, 'b'},
        {"node-a", required_argument, NULL, 'A'},   {"node-b", required_argument, NULL, 'B'},
        {"count", required_argument, NULL, 'n'},    {"warmup", required_argument, NULL, 'w'},
        {"gap-us", required_argument, NULL, 'g'},   {NULL, 0, NULL, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        switch (c) {
        case 'a': sock[0] = optarg; break;
        case 'b': sock[1] = optarg; break;
        case 'A': node[0] = atoi(optarg); break;
        case 'B': node[1] = atoi(optarg); break;
        case 'n': count = atol(optarg); break;
        case 'w': warmup = atol(optarg); break;
        case 'g': gap_us = atol(optarg); break;
        default:
            fputs("usage: ima-xch-bench --socket-a PATH --socket-b PATH [--node-a 1] "
                  "[--node-b 2] [--count 1000] [--warmup 50] [--gap-us 1000]\n",
                  stderr);
            return 2;
        }
    }
    if (!sock[0] || !sock[1] || count < 1 || warmup < 0 || gap_us < 0 || node[0] == node[1]) {
        fputs("ima-xch-bench: --socket-a and --socket-b are required (two different nodes)\n",
              stderr);
        return 2;
    }
    xch_client_t cl[2];
    char err[256];
    for (int i = 0; i < 2; i++)
        if (xch_client_connect(&cl[i], sock[i], (unsigned)node[i], err, sizeof err) != 0) {
            fprintf(stderr, "ima-xch-bench: %s\n", err);
            return 1;
        }
    int64_t *lat = malloc((size_t)count * sizeof *lat);
    if (!lat)
        return 1;
    uint32_t wait = (1u << (node[0] - 1)) | (1u << (node[1] - 1));
    long got = 0, incomplete = 0;
    for (long r = 0; r < warmup + count; r++) {
        uint32_t frame = (uint32_t)r;
        int64_t t_ns = (int64_t)r * 50000000;
        struct xch_inputs in[2];
        memset(in, 0, sizeof in);
        for (int i = 0; i < 2; i++) {
            in[i].valid = XCH_IN_GPS;
            in[i].wait_mask = wait;
            in[i].gps_seq = frame;
            in[i].gps[0] = node[i];
        }
        struct xch_agreed g[2];
        int rc = xch_client_send(&cl[0], XCH_INPUTS, frame, t_ns, &in[0], sizeof in[0]);
        sleep_us(gap_us);
        int64_t t0 = mono_ns();
        if (rc == 0)
            rc = xch_client_send(&cl[1], XCH_INPUTS, frame, t_ns, &in[1], sizeof in[1]);
        if (rc == 0)
            rc = xch_client_await(&cl[0], frame, &g[0], 10000);
        int64_t t1 = mono_ns();
        if (rc == 0)
            rc = xch_client_await(&cl[1], frame, &g[1], 10000);
        if (rc != 0) {
            fprintf(stderr, "ima-xch-bench: round %ld: %s\n", r, strerror(-rc));
            return 1;
        }
        bool complete = (g[0].present & wait) == wait && (g[1].present & wait) == wait;
        if (!complete)
            incomplete++;
        if (r >= warmup && complete)
            lat[got++] = t1 - t0;
        sleep_us(gap_us);
    }
    xch_client_close(&cl[0]);
    xch_client_close(&cl[1]);
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
           lat[got - 1] / 1000.0, gap_us);
    free(lat);
    return 0;
}
