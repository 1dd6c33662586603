/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the CAN wire model when memory runs out. Every scenario below (a plain frame,
 * each fault class, a bus-off) runs again and again with its first, second, third, ...
 * allocation failing (realloc is wrapped at link time): each time the model either reports
 * CANBUS_WIRE_ENOMEM from the call that needed the memory or only loses the event record it
 * could not store; it never crashes, never returns another error, and frees everything
 * (the sanitizer build checks the leaks). Also the arguments canbus_wire_add_fault refuses. */
#include "canbus__wire.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "canbus_test.h"

void *__real_realloc(void *p, size_t n);
void *__wrap_realloc(void *p, size_t n);

static long fail_countdown = -1; /* the allocation that fails: 0 = the next one; < 0: none */
static long failed;               /* allocations failed on purpose */

void *__wrap_realloc(void *p, size_t n)
{
    if (fail_countdown == 0) {
        fail_countdown = -1;
        failed++;
        return NULL;
    }
    if (fail_countdown > 0)
        fail_countdown--;
    return __real_realloc(p, n);
}

static const uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8};

/* The first error of a scenario's calls, or 0. */
#define STEP(call)                                                                            \
    do {                                                                                      \
        int rc_ = (call);                                                                     \
        if (rc_)                                                                              \
            return rc_;                                                                       \
    } while (0)

static int with_fault(canbus_wire_t *w, canbus_fault_t f)
{
    if (!f.until_ns)
        f.until_ns = INT64_MAX;
    return canbus_wire_add_fault(w, &f);
}

static int frames(canbus_wire_t *w, int n, uint32_t id, uint8_t client)
{
    for (int i = 0; i < n; i++)
        STEP(canbus_wire_submit(w, i * 100000, id + (uint32_t)(i % 4), 0, 8, data, client));
    return 0;
}

static int plain(canbus_wire_t *w)
{
    STEP(frames(w, 300, 0x100, 0)); /* past the frame heaps' first 256 */
    return canbus_wire_run(w, 40000000);
}

static int corrupt(canbus_wire_t *w)
{
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_CORRUPT, .target = CANBUS_ANY,
                                        .match_id = 0x100, .limit = 2}));
    STEP(frames(w, 4, 0x100, 1));
    return canbus_wire_run(w, 5000000);
}

static int drop_and_delay(canbus_wire_t *w)
{
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_DROP, .target = CANBUS_ANY,
                                        .match_id = 0x100, .limit = 1}));
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_DELAY, .target = 1,
                                        .match_id = CANBUS_ANY_ID, .delay_ns = 2000000}));
    STEP(frames(w, 2, 0x100, 0));
    STEP(frames(w, 2, 0x200, 1));
    return canbus_wire_run(w, 10000000);
}

static int babble(canbus_wire_t *w)
{
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_BABBLE, .target = CANBUS_ANY,
                                        .match_id = CANBUS_ANY_ID, .from_ns = 1000000,
                                        .until_ns = 2000000, .babble_len = 8}));
    STEP(frames(w, 2, 0x10, 0));
    return canbus_wire_run(w, 5000000);
}

static int duplicate_and_cut(canbus_wire_t *w)
{
    canbus_wire_attach(w, 0, true);
    canbus_wire_attach(w, 1, true);
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_DUPLICATE, .target = CANBUS_ANY,
                                        .match_id = 0x100, .limit = 1}));
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_CUT, .target = 1,
                                        .match_id = CANBUS_ANY_ID, .from_ns = 1000000}));
    STEP(frames(w, 2, 0x100, 0));
    STEP(canbus_wire_submit(w, 1500000, 0x300, 0, 1, data, 1));
    return canbus_wire_run(w, 5000000);
}

static int bus_off(canbus_wire_t *w)
{
    canbus_wire_arm_recovery(w, 0, true);
    STEP(with_fault(w, (canbus_fault_t){.kind = CANBUS_FAULT_BUS_OFF, .target = 0,
                                        .match_id = CANBUS_ANY_ID, .from_ns = 500000,
                                        .until_ns = 3000000}));
    STEP(frames(w, 20, 0x100, 0));
    return canbus_wire_run(w, 20000000);
}

static const struct {
    const char *name;
    int (*run)(canbus_wire_t *);
} scenarios[] = {
    {"plain", plain},   {"corrupt", corrupt}, {"drop_and_delay", drop_and_delay},
    {"babble", babble}, {"duplicate_and_cut", duplicate_and_cut}, {"bus_off", bus_off},
};

static void test_every_allocation_failing_in_turn(void)
{
    for (size_t s = 0; s < sizeof scenarios / sizeof scenarios[0]; s++) {
        canbus_wire_t w;
        CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
        CHECK_EQ(scenarios[s].run(&w), 0);
        uint64_t events = w.n_ev;
        CHECK(events > 0);
        canbus_wire_fini(&w);
        long reported = 0;
        for (long k = 0;; k++) {
            CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
            long before = failed;
            fail_countdown = k;
            int rc = scenarios[s].run(&w);
            bool hit = failed != before;
            fail_countdown = -1;
            canbus_wire_fini(&w);
            if (!hit) {
                CHECK_EQ(rc, 0); /* no allocation left to fail: the clean run again */
                break;
            }
            if (rc != 0 && rc != CANBUS_WIRE_ENOMEM)
                fprintf(stderr, "scenario %s, allocation %ld: %d\n", scenarios[s].name, k, rc);
            CHECK(rc == 0 || rc == CANBUS_WIRE_ENOMEM);
            reported += rc == CANBUS_WIRE_ENOMEM;
        }
        if (reported == 0)
            fprintf(stderr, "scenario %s: no failure reported\n", scenarios[s].name);
        CHECK(reported > 0);
    }
}

static void test_faults_it_refuses(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 999, 0), CANBUS_WIRE_EINVAL);
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    CHECK_EQ(with_fault(&w, (canbus_fault_t){.kind = 0}), CANBUS_WIRE_EINVAL);
    CHECK_EQ(with_fault(&w, (canbus_fault_t){.kind = CANBUS_FAULT_KINDS + 1}), CANBUS_WIRE_EINVAL);
    CHECK_EQ(with_fault(&w, (canbus_fault_t){.kind = CANBUS_FAULT_BABBLE, .babble_len = 9}),
             CANBUS_WIRE_EINVAL);
    CHECK_EQ(with_fault(&w, (canbus_fault_t){.kind = CANBUS_FAULT_DROP, .period_ns = -1}),
             CANBUS_WIRE_EINVAL);
    CHECK_EQ(with_fault(&w, (canbus_fault_t){.kind = CANBUS_FAULT_DROP, .period_ns = 10,
                                             .on_ns = 11}),
             CANBUS_WIRE_EINVAL);
    CHECK_EQ(with_fault(&w, (canbus_fault_t){.kind = CANBUS_FAULT_DROP, .period_ns = 10}),
             CANBUS_WIRE_EINVAL);
    CHECK_EQ(w.n_faults, 0);
    /* Events name a fault by a 16-bit index: the table stops short of it. */
    int rc = 0;
    while (rc == 0)
        rc = with_fault(&w, (canbus_fault_t){.kind = CANBUS_FAULT_DROP, .match_id = 1});
    CHECK_EQ(rc, CANBUS_WIRE_EFULL);
    CHECK_EQ(w.n_faults, UINT16_MAX - 1);
    /* As bad: frames the wire cannot carry. */
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x800, 0, 1, data, 0), CANBUS_WIRE_EINVAL);
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x1, 0, 9, data, 0), CANBUS_WIRE_EINVAL);
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x1, 0, 1, data, CANBUS_WIRE_MAX_CLIENTS),
             CANBUS_WIRE_EINVAL);
    canbus_wire_fini(&w);
}

int main(void)
{
    test_every_allocation_failing_in_turn();
    test_faults_it_refuses();
    if (unit_failures) {
        fprintf(stderr, "%d check(s) failed\n", unit_failures);
        return 1;
    }
    printf("ok   test_canbus_wire_oom (%ld allocations failed on purpose)\n", failed);
    return 0;
}
