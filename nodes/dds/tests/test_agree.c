/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the agent's agreement rules (agent__agree.h): who is waited for, what AGREED holds. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "agent__agree.h"

static int failures;

#define CHECK_EQ(a, e)                                                                        \
    do {                                                                                      \
        intmax_t a_ = (intmax_t)(a), e_ = (intmax_t)(e);                                      \
        if (a_ != e_) {                                                                       \
            fprintf(stderr, "%s:%d: %s == %s: got %jd, expected %jd\n", __FILE__, __LINE__,   \
                    #a, #e, a_, e_);                                                          \
            failures++;                                                                       \
        }                                                                                     \
    } while (0)

static struct xch_inputs in_of(unsigned node, uint32_t frame)
{
    struct xch_inputs x;
    memset(&x, 0, sizeof x);
    x.valid = XCH_IN_GPS;
    x.gps_seq = node * 1000 + frame;
    x.wait_mask = 7;
    return x;
}

static void store(agree_t *a, unsigned node, uint32_t frame)
{
    struct xch_inputs x = in_of(node, frame);
    agree_store(a, node, frame, (int64_t)frame * 50000000, &x);
}

static void test_waits_for_mask_members_only(void)
{
    agree_t a;
    agree_init(&a, 1, 3);
    store(&a, 1, 10);
    CHECK_EQ(agree_missing(&a, 10, 0x7), 0x6);
    CHECK_EQ(agree_missing(&a, 10, 0x3), 0x2);
    CHECK_EQ(agree_missing(&a, 10, 0x1), 0); /* itself is never waited for */
    CHECK_EQ(agree_missing(&a, 10, 0xF8), 0); /* bits beyond the system are ignored */
    store(&a, 2, 10);
    CHECK_EQ(agree_missing(&a, 10, 0x7), 0x4);
    store(&a, 3, 10);
    CHECK_EQ(agree_missing(&a, 10, 0x7), 0);
}

static void test_agreed_holds_self_and_mask_members(void)
{
    agree_t a;
    agree_init(&a, 2, 3);
    store(&a, 1, 5);
    store(&a, 2, 5);
    store(&a, 3, 5);
    struct xch_agreed g;
    agree_build(&a, 5, 0x1, &g); /* node 3 published but is not awaited: left out */
    CHECK_EQ(g.present, 0x3);
    CHECK_EQ(g.in[0].gps_seq, 1005);
    CHECK_EQ(g.in[1].gps_seq, 2005);
    CHECK_EQ(g.in[2].gps_seq, 0);
}

static void test_dead_and_withdrawn_are_not_waited_for(void)
{
    agree_t a;
    agree_init(&a, 1, 3);
    store(&a, 1, 1);
    agree_set_dead(&a, 2);
    CHECK_EQ(agree_missing(&a, 1, 0x7), 0x4);
    agree_set_withdrawn(&a, 3);
    CHECK_EQ(agree_missing(&a, 1, 0x7), 0);
    /* a dead node's sample that did arrive is still used */
    store(&a, 2, 2);
    store(&a, 1, 2);
    struct xch_agreed g;
    agree_build(&a, 2, 0x7, &g);
    CHECK_EQ(g.present, 0x3);
}

static void test_withdrawn_node_counts_again_after_its_first_frame(void)
{
    agree_t a;
    agree_init(&a, 1, 2);
    struct xch_agreed g;
    for (uint32_t f = 0; f < 3; f++) {
        store(&a, 1, f);
        store(&a, 2, f);
        agree_build(&a, f, 0x3, &g);
        CHECK_EQ(g.present, 0x3);
    }
    agree_set_withdrawn(&a, 2); /* node 2's io drops after frame 2 */
    store(&a, 1, 3);
    CHECK_EQ(agree_missing(&a, 3, 0x3), 0);
    agree_build(&a, 3, 0x3, &g);
    CHECK_EQ(g.present, 0x1);
    /* its io is back at frame 4: whether frame 4's sample came before the request or after,
     * frame 4 leaves it out */
    store(&a, 1, 4);
    CHECK_EQ(agree_missing(&a, 4, 0x3), 0);
    store(&a, 2, 4);
    agree_build(&a, 4, 0x3, &g);
    CHECK_EQ(g.present, 0x1);
    /* from frame 5 on it is waited for and included */
    store(&a, 1, 5);
    CHECK_EQ(agree_missing(&a, 5, 0x3), 0x2);
    store(&a, 2, 5);
    agree_build(&a, 5, 0x3, &g);
    CHECK_EQ(g.present, 0x3);
    /* a stale sample also marks the resumption */
    agree_set_withdrawn(&a, 2);
    store(&a, 2, 5);
    store(&a, 1, 6);
    CHECK_EQ(agree_missing(&a, 6, 0x3), 0x2);
}

static void test_a_node_past_the_frame_is_not_waited_for(void)
{
    agree_t a;
    agree_init(&a, 1, 2);
    store(&a, 1, 7);
    store(&a, 2, 8); /* node 2 skipped frame 7 (its io restarted) */
    CHECK_EQ(agree_missing(&a, 7, 0x3), 0);
    struct xch_agreed g;
    agree_build(&a, 7, 0x3, &g);
    CHECK_EQ(g.present, 0x1);
    store(&a, 1, 8);
    CHECK_EQ(agree_missing(&a, 8, 0x3), 0);
    agree_build(&a, 8, 0x3, &g);
    CHECK_EQ(g.present, 0x3);
}

static void test_stale_samples_are_dropped(void)
{
    agree_t a;
    agree_init(&a, 1, 2);
    store(&a, 1, 3);
    store(&a, 2, 3);
    struct xch_agreed g;
    agree_build(&a, 3, 0x3, &g);
    uint64_t before = a.stale;
    store(&a, 2, 3); /* answered already */
    store(&a, 2, 2);
    CHECK_EQ(a.stale - before, 2);
    /* a later frame takes its ring slot: the older one cannot come back */
    store(&a, 2, 4 + AGREE_RING);
    store(&a, 2, 5);
    CHECK_EQ(a.stale - before, 2);
    store(&a, 2, 4);
    CHECK_EQ(a.stale - before, 3);
}

static void test_same_publications_same_agreed(void)
{
    /* Two agents that receive the same samples in different orders build the same AGREED. */
    agree_t x, y;
    agree_init(&x, 1, 3);
    agree_init(&y, 1, 3);
    store(&x, 1, 4);
    store(&x, 2, 4);
    store(&x, 3, 4);
    store(&y, 3, 4);
    store(&y, 3, 5);
    store(&y, 2, 4);
    store(&y, 1, 4);
    struct xch_agreed gx, gy;
    agree_build(&x, 4, 0x7, &gx);
    agree_build(&y, 4, 0x7, &gy);
    CHECK_EQ(memcmp(&gx, &gy, sizeof gx), 0);
}

static void test_lost_frames_are_neither_waited_for_nor_included(void)
{
    agree_t a;
    agree_init(&a, 1, 3);
    store(&a, 1, 7);
    store(&a, 2, 7);
    CHECK_EQ(agree_missing(&a, 7, 0x7), 0x4);
    CHECK_EQ(agree_store_lost(&a, 3, 7, 7 * 50000000LL), 1); /* node 3's inputs of 7: lost */
    CHECK_EQ(agree_missing(&a, 7, 0x7), 0);
    struct xch_agreed g;
    agree_build(&a, 7, 0x7, &g);
    CHECK_EQ(g.present, 0x3);
    CHECK_EQ(a.lost, 1);
    /* a late real sample of frame 7 before the answer does not undo the mark */
    agree_t b;
    agree_init(&b, 1, 3);
    CHECK_EQ(agree_store_lost(&b, 3, 7, 0), 1);
    store(&b, 3, 7);
    CHECK_EQ(b.stale, 1);
    store(&b, 1, 7);
    store(&b, 2, 7);
    agree_build(&b, 7, 0x7, &g);
    CHECK_EQ(g.present, 0x3);
    /* the late real sample of frame 7 comes after the answer: stale, changes nothing */
    uint64_t stale = a.stale;
    store(&a, 3, 7);
    CHECK_EQ(a.stale - stale, 1);
    /* the next frame is waited for again, and included */
    store(&a, 1, 8);
    store(&a, 2, 8);
    CHECK_EQ(agree_missing(&a, 8, 0x7), 0x4);
    store(&a, 3, 8);
    agree_build(&a, 8, 0x7, &g);
    CHECK_EQ(g.present, 0x7);
    /* a node's own inputs are never lost to itself */
    CHECK_EQ(agree_store_lost(&a, 1, 9, 0), 0);
}

int main(void)
{
    test_waits_for_mask_members_only();
    test_agreed_holds_self_and_mask_members();
    test_dead_and_withdrawn_are_not_waited_for();
    test_withdrawn_node_counts_again_after_its_first_frame();
    test_a_node_past_the_frame_is_not_waited_for();
    test_stale_samples_are_dropped();
    test_same_publications_same_agreed();
    test_lost_frames_are_neither_waited_for_nor_included();
    if (failures) {
        fprintf(stderr, "test_xch_agree: %d check(s) failed\n", failures);
        return 1;
    }
    puts("test_xch_agree: ok");
    return 0;
}
