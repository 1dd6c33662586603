/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the cyclic plan: the sequence of window activations in module time. */
#include <stdlib.h>
#include <string.h>

#include "ske/config.h"
#include "ske/plan.h"
#include "ske_test.h"

static ske_module_cfg_t *load_example(void)
{
    ske_load_opts_t opts = {.schema_dir = IMA_SOURCE_DIR "/config/schema", .resolve_executables = false};
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    if (ske_config_load(IMA_SOURCE_DIR "/config/examples/three_partitions.xml", &opts, &m, &d) != SKE_OK)
        return NULL;
    return m;
}

/* The example: producer [0,10) ms, consumer [10,22), producer [30,35), monitor [38,46). */
static void test_sequence_over_frames(void)
{
    ske_module_cfg_t *m = load_example();
    REQUIRE(m != NULL);
    static const struct { const char *partition; int64_t off, dur; } expect[] = {
        {"producer", 0, 10000000}, {"consumer", 10000000, 12000000},
        {"producer", 30000000, 5000000}, {"monitor", 38000000, 8000000},
    };
    ske_slot_t s;
    ske_plan_first(m, &s);
    int64_t prev_end = 0;
    for (int frame = 0; frame < 3; frame++) {
        for (int i = 0; i < 4; i++) {
            CHECK_EQ(s.frame, frame);
            CHECK_EQ(s.index, i);
            CHECK_STR(m->partitions[s.window->partition].name, expect[i].partition);
            CHECK_EQ(s.start_ns, frame * 50000000LL + expect[i].off);
            CHECK_EQ(s.end_ns, s.start_ns + expect[i].dur);
            CHECK(s.start_ns >= prev_end); /* one partition at a time, in time order */
            prev_end = s.end_ns;
            ske_plan_next(m, &s);
        }
    }
    CHECK_EQ(s.frame, 3);
    CHECK_EQ(s.index, 0);
    CHECK_EQ(s.start_ns, 150000000);
    ske_config_free(m);
}

static void test_slot_at_a_time(void)
{
    ske_module_cfg_t *m = load_example();
    REQUIRE(m != NULL);
    ske_slot_t s;
    ske_plan_at(m, 0, &s); /* inside the first window */
    CHECK_EQ(s.frame, 0);
    CHECK_EQ(s.index, 0);
    ske_plan_at(m, 9999999, &s); /* last nanosecond of it */
    CHECK_EQ(s.index, 0);
    ske_plan_at(m, 10000000, &s); /* windows are half-open: the next one */
    CHECK_EQ(s.index, 1);
    ske_plan_at(m, 25000000, &s); /* in the gap: the window to come */
    CHECK_EQ(s.index, 2);
    CHECK_EQ(s.start_ns, 30000000);
    ske_plan_at(m, 47000000, &s); /* after the last window: next frame's first */
    CHECK_EQ(s.frame, 1);
    CHECK_EQ(s.index, 0);
    CHECK_EQ(s.start_ns, 50000000);
    ske_plan_at(m, 7 * 50000000LL + 40000000, &s); /* a later frame */
    CHECK_EQ(s.frame, 7);
    CHECK_EQ(s.index, 3);
    ske_plan_at(m, -5, &s); /* before time 0: the first window */
    CHECK_EQ(s.frame, 0);
    CHECK_EQ(s.index, 0);
    ske_config_free(m);
}

static void test_time_per_partition(void)
{
    ske_module_cfg_t *m = load_example();
    REQUIRE(m != NULL);
    int64_t total = 0;
    for (int i = 0; i < m->n_partitions; i++)
        total += ske_plan_partition_ns(m, i);
    CHECK_EQ(ske_plan_partition_ns(m, ske_config_partition_by_id(m, 1)), 15000000);
    CHECK_EQ(ske_plan_partition_ns(m, ske_config_partition_by_id(m, 2)), 12000000);
    CHECK_EQ(ske_plan_partition_ns(m, ske_config_partition_by_id(m, 3)), 8000000);
    CHECK_EQ(ske_plan_idle_ns(m), 50000000 - total);
    CHECK_EQ(ske_plan_idle_ns(m), 15000000);
    ske_config_free(m);
}

/* A module of one window that fills the whole frame: activations follow each other with no
 * gap, frame after frame. */
static void test_single_window_fills_the_frame(void)
{
    ske_module_cfg_t *m = calloc(1, sizeof *m);
    REQUIRE(m != NULL);
    m->major_frame_ns = 1000;
    m->n_partitions = 1;
    m->n_windows = 1;
    m->windows[0] = (ske_window_cfg_t){.id = 1, .partition = 0, .offset_ns = 0, .duration_ns = 1000};
    ske_slot_t s;
    ske_plan_first(m, &s);
    for (int k = 0; k < 5; k++) {
        CHECK_EQ(s.frame, k);
        CHECK_EQ(s.start_ns, k * 1000);
        CHECK_EQ(s.end_ns, (k + 1) * 1000);
        ske_plan_next(m, &s);
    }
    CHECK_EQ(ske_plan_idle_ns(m), 0);
    free(m);
}

int main(void)
{
    RUN(test_sequence_over_frames);
    RUN(test_slot_at_a_time);
    RUN(test_time_per_partition);
    RUN(test_single_window_fills_the_frame);
    return ske_test_result();
}
