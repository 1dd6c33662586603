/* SPDX-License-Identifier: Apache-2.0 */
/* The mission manager core's CPU time per cycle (`ima bench mission`): a plan image flown for
 * N cycles by the kinematic aircraft of the unit tests, each mm_step timed on this thread's
 * CPU clock. Prints one JSON object: cycles, median, p99 and max microseconds.
 * Usage: mission_manager_bench PLAN.img CYCLES */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "../test/kinematic.h"

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec / 1e3;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: mission_manager_bench PLAN.img CYCLES\n");
        return 2;
    }
    static unsigned char image[RPAS_PLAN_MAX_BYTES];
    FILE *f = fopen(argv[1], "rb");
    if (!f) {
        perror(argv[1]);
        return 2;
    }
    size_t len = fread(image, 1, sizeof image, f);
    fclose(f);
    long n = atol(argv[2]);
    if (n < 100) {
        fprintf(stderr, "mission_manager_bench: at least 100 cycles\n");
        return 2;
    }
    double *us = malloc((size_t)n * sizeof *us);
    if (!us)
        return 1;
    uint32_t crc = rpas_crc32(image, len);
    mm_t mm;
    mm_init(&mm, NULL);
    ac_t a;
    ac_init(&a);
    world_t w = {.c2_up = true, .gps_ok = true, .fcs_mission = true, .agreed_crc = crc};
    for (long k = 0; k < n; k++) {
        mm_inputs_t in;
        inputs(&a, &w, &in);
        if (k == 0) {
            in.plan = image;
            in.plan_len = len;
            in.plan_crc = crc;
        }
        rpas_mission_msg_t m;
        rpas_mm_status_msg_t st;
        double t0 = now_us();
        bool out = mm_step(&mm, &in, a.t, &m, &st);
        us[k] = now_us() - t0;
        if (out)
            ac_step(&a, &m);
        else
            a.t += 50000000;
    }
    qsort(us, (size_t)n, sizeof *us, cmp);
    printf("{\"cycles\": %ld, \"median_us\": %.3f, \"p99_us\": %.3f, \"max_us\": %.3f, "
           "\"plan_loaded\": %s}\n",
           n, us[n / 2], us[(long)(0.99 * (double)(n - 1))], us[n - 1],
           mm.plan.loaded ? "true" : "false");
    free(us);
    return mm.plan.loaded ? 0 : 1;
}
