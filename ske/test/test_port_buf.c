/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the port memory shared by the SKE and the APEX library: sampling slots,
 * queues and the sizes both sides map. */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ske_abi.h"
#include "ske_test.h"

/* Port memory as the SKE gives it: page-aligned, zero-filled, exactly map_size bytes (so the
 * sanitizer build catches any access past the mapping). */
static void *port_mem(size_t size)
{
    void *m = aligned_alloc(4096, size);
    if (m)
        memset(m, 0xa5, size); /* init must not rely on fresh memory being zero */
    return m;
}

static ske_slot_hdr_t *sampling_slot(void *mem, uint32_t max_size, uint32_t i)
{
    return (ske_slot_hdr_t *)((char *)mem + sizeof(ske_sampling_hdr_t) +
                              (size_t)i * ske_slot_stride(max_size));
}

static ske_slot_hdr_t *queue_slot(void *mem, uint32_t max_size, uint32_t i)
{
    return (ske_slot_hdr_t *)((char *)mem + sizeof(ske_queue_hdr_t) +
                              (size_t)i * ske_slot_stride(max_size));
}

static size_t page_round(size_t n)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    return (n + page - 1) / page * page;
}

/* ---- sizes ---------------------------------------------------------------------------- */

static void test_layout(void)
{
    /* Both sides compile these layouts: a change is an ABI change (SKE_ABI_VERSION). */
    CHECK_EQ_U(sizeof(ske_sampling_hdr_t), 16);
    CHECK_EQ_U(sizeof(ske_slot_hdr_t), 16);
    CHECK_EQ_U(sizeof(ske_queue_hdr_t), 32);
    /* Slots keep their int64 timestamp aligned. */
    for (uint32_t m = 1; m <= 64; m++) {
        CHECK_EQ_U(ske_slot_stride(m) % 8, 0);
        CHECK(ske_slot_stride(m) >= sizeof(ske_slot_hdr_t) + m);
        CHECK(ske_slot_stride(m) < sizeof(ske_slot_hdr_t) + m + 8);
    }
    CHECK_EQ_U(ske_slot_stride(64), 16 + 64);
    CHECK_EQ_U(ske_slot_stride(65), 16 + 72);
}

static void test_map_sizes_are_page_rounded(void)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    static const uint32_t sizes[] = {1, 7, 8, 64, 2024, 2025, 4096, 65536, 1u << 20};
    static const uint32_t caps[] = {1, 3, 8, 16, 1000, 1u << 20};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        uint32_t m = sizes[i];
        size_t need = sizeof(ske_sampling_hdr_t) + 2 * ske_slot_stride(m);
        size_t got = ske_sampling_map_size(m);
        CHECK_EQ_U(got % page, 0);
        CHECK_EQ_U(got, page_round(need));
        for (size_t j = 0; j < sizeof caps / sizeof caps[0]; j++) {
            uint32_t c = caps[j];
            /* 64-bit arithmetic: 1 MiB messages × 1 Mi slots must not wrap. */
            /* Slots are a power of two at least the capacity (index wrap-around). */
            uint64_t slots = 1;
            while (slots < c)
                slots <<= 1;
            uint64_t qneed = sizeof(ske_queue_hdr_t) + slots * ske_slot_stride(m);
            size_t qgot = ske_queue_map_size(m, c);
            CHECK_EQ_U(qgot % page, 0);
            CHECK_EQ_U(qgot, page_round((size_t)qneed));
        }
    }
    /* Exact fits stay one page; one byte more takes the next page. */
    CHECK_EQ_U(ske_sampling_map_size(2024), 4096); /* 16 + 2 × (16 + 2024) = 4096 */
    CHECK_EQ_U(ske_sampling_map_size(2025), 8192);
    CHECK_EQ_U(ske_queue_map_size(4048, 1), 4096); /* 32 + 16 + 4048 = 4096 */
    CHECK_EQ_U(ske_queue_map_size(4049, 1), 8192);
    CHECK_EQ_U(ske_queue_map_size(32, 8), 4096);
}

/* ---- sampling ------------------------------------------------------------------------- */

static void test_sampling_empty(void)
{
    const uint32_t max = 64;
    void *mem = port_mem(ske_sampling_map_size(max));
    REQUIRE(mem);
    ske_sampling_init(mem, max);
    const ske_sampling_hdr_t *h = mem;
    CHECK_EQ_U(h->max_size, max);
    CHECK_EQ_U(atomic_load(&h->seq), 0);

    uint8_t buf[64];
    uint32_t len = 12345;
    int64_t t = -7;
    CHECK(!ske_sampling_read(mem, max, buf, &len, &t));
    /* Nothing is reported for an empty port. */
    CHECK_EQ_U(len, 12345);
    CHECK_EQ(t, -7);
    free(mem);
}

static void test_sampling_round_trip(void)
{
    const uint32_t max = 64;
    void *mem = port_mem(ske_sampling_map_size(max));
    REQUIRE(mem);
    ske_sampling_init(mem, max);
    ske_sampling_write(mem, max, "hello", 5, 123456789);

    uint8_t buf[64] = {0};
    uint32_t len = 0;
    int64_t t = 0;
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, 5);
    CHECK(memcmp(buf, "hello", 5) == 0);
    CHECK_EQ(t, 123456789);

    /* A read does not consume: the same message again. */
    memset(buf, 0, sizeof buf);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, 5);
    CHECK(memcmp(buf, "hello", 5) == 0);

    /* A full-size message and an empty one. */
    uint8_t full[64];
    for (int i = 0; i < 64; i++)
        full[i] = (uint8_t)(i * 3 + 1);
    ske_sampling_write(mem, max, full, 64, 5);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, 64);
    CHECK(memcmp(buf, full, 64) == 0);
    ske_sampling_write(mem, max, "", 0, 6);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, 0);
    CHECK_EQ(t, 6);
    free(mem);
}

static void test_sampling_latest_wins(void)
{
    const uint32_t max = 16;
    void *mem = port_mem(ske_sampling_map_size(max));
    REQUIRE(mem);
    ske_sampling_init(mem, max);
    ske_sampling_write(mem, max, "first message", 13, 1);
    ske_sampling_write(mem, max, "second", 6, 2);
    ske_sampling_write(mem, max, "3rd", 3, 3);

    char buf[16] = {0};
    uint32_t len = 0;
    int64_t t = 0;
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, 3); /* not the length of an older, longer message */
    CHECK(memcmp(buf, "3rd", 3) == 0);
    CHECK_EQ(t, 3);
    CHECK_EQ_U(atomic_load(&((ske_sampling_hdr_t *)mem)->seq), 3);
    free(mem);
}

static void test_sampling_length_clamped(void)
{
    const uint32_t max = 24;
    void *mem = port_mem(ske_sampling_map_size(max));
    REQUIRE(mem);
    ske_sampling_init(mem, max);
    /* The reader's buffer is exactly max_size bytes: the sanitizer build catches an overrun. */
    uint8_t *buf = malloc(max);
    REQUIRE(buf);
    uint32_t len = 0;
    int64_t t = 0;

    ske_sampling_write(mem, max, "abcdefgh", 8, 10);
    ske_sampling_hdr_t *h = mem;
    ske_slot_hdr_t *s = sampling_slot(mem, max, atomic_load(&h->seq) & 1u);
    CHECK_EQ_U(s->len, 8);

    /* The destination maps port memory the source can write: a hostile or broken writer may
     * put any length in the slot header. */
    static const uint32_t bad[] = {25, 4096, UINT32_MAX};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        s->len = bad[i];
        len = 0;
        CHECK(ske_sampling_read(mem, max, buf, &len, &t));
        CHECK_EQ_U(len, max);
        CHECK(memcmp(buf, "abcdefgh", 8) == 0);
    }
    /* A corrupted max_size in the port header is not trusted either: the caller's is. */
    h->max_size = UINT32_MAX;
    s->len = UINT32_MAX;
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, max);

    /* Writer side: an oversize message is cut to the slot rather than written past it. */
    ske_sampling_init(mem, max);
    uint8_t big[100];
    memset(big, 'x', sizeof big);
    ske_sampling_write(mem, max, big, sizeof big, 11);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, max);
    free(buf);
    free(mem);
}

static void test_sampling_writer_stopped_mid_write(void)
{
    const uint32_t max = 32;
    void *mem = port_mem(ske_sampling_map_size(max));
    REQUIRE(mem);
    ske_sampling_init(mem, max);
    ske_sampling_hdr_t *h = mem;
    const char a[] = "message A, complete";
    ske_sampling_write(mem, max, a, sizeof a, 1000);
    uint32_t seq_a = atomic_load(&h->seq);

    /* The writer starts B in the slot readers do not see and is stopped (end of its window,
     * SIGSTOP, crash) before it publishes: header and half of the payload written. */
    uint32_t other = (seq_a + 1u) & 1u;
    CHECK(other != (seq_a & 1u));
    ske_slot_hdr_t *s = sampling_slot(mem, max, other);
    s->t_ns = 2000;
    s->len = 30;
    s->seq = seq_a + 1u;
    memcpy(s + 1, "BBBBBBBBBBBBBBB", 15);

    char buf[32] = {0};
    uint32_t len = 0;
    int64_t t = 0;
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, sizeof a);
    CHECK(memcmp(buf, a, sizeof a) == 0);
    CHECK_EQ(t, 1000);
    CHECK_EQ_U(atomic_load(&h->seq), seq_a);

    /* The writer comes back and writes B in full: B is published, and A's slot was not
     * touched, so a reader that loaded seq just before B's publication still copies all of A. */
    const char b[] = "message B";
    ske_sampling_write(mem, max, b, sizeof b, 3000);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK_EQ_U(len, sizeof b);
    CHECK(memcmp(buf, b, sizeof b) == 0);
    CHECK_EQ(t, 3000);
    ske_slot_hdr_t *sa = sampling_slot(mem, max, seq_a & 1u);
    CHECK_EQ_U(sa->len, sizeof a);
    CHECK(memcmp(sa + 1, a, sizeof a) == 0);
    free(mem);
}

static void test_sampling_sequence_wraps(void)
{
    const uint32_t max = 8;
    void *mem = port_mem(ske_sampling_map_size(max));
    REQUIRE(mem);
    ske_sampling_init(mem, max);
    ske_sampling_hdr_t *h = mem;
    ske_sampling_write(mem, max, "A", 1, 1); /* seq 1: slot 1 */
    /* 2^32 - 2 writes later: seq is odd again, slot 1 still holds the latest message. */
    atomic_store(&h->seq, UINT32_MAX);

    char buf[8];
    uint32_t len = 0;
    int64_t t = 0;
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK(len == 1 && buf[0] == 'A');
    /* The next write must neither make the port look empty (seq 0) nor reuse slot 1. */
    ske_sampling_write(mem, max, "B", 1, 2);
    CHECK(atomic_load(&h->seq) != 0);
    CHECK_EQ_U(atomic_load(&h->seq) & 1u, 0);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK(len == 1 && buf[0] == 'B');
    CHECK_EQ(t, 2);
    CHECK(memcmp(sampling_slot(mem, max, 1) + 1, "A", 1) == 0);
    ske_sampling_write(mem, max, "C", 1, 3);
    CHECK(ske_sampling_read(mem, max, buf, &len, &t));
    CHECK(len == 1 && buf[0] == 'C');
    free(mem);
}

/* ---- queues --------------------------------------------------------------------------- */

/* Message i of a test sequence: "m<i>" padded with i+1 copies of a letter. */
static uint32_t make_msg(uint32_t i, char *out, uint32_t max)
{
    int n = snprintf(out, max, "m%u", i);
    uint32_t len = (uint32_t)n;
    while (len < max && len < (uint32_t)n + 1 + (i % 5))
        out[len++] = (char)('a' + i % 26);
    return len;
}

static void check_peek(const void *mem, uint32_t max, uint32_t cap, uint32_t tail, uint32_t i)
{
    char want[32], got[32];
    uint32_t want_len = make_msg(i, want, max), len = 0;
    int64_t t = 0;
    ske_queue_peek(mem, max, cap, tail, got, &len, &t);
    CHECK_EQ_U(len, want_len);
    CHECK(memcmp(got, want, want_len) == 0);
    CHECK_EQ(t, (int64_t)i * 10);
}

static void test_queue_fill_and_fifo(void)
{
    const uint32_t max = 16, cap = 4;
    void *mem = port_mem(ske_queue_map_size(max, cap));
    REQUIRE(mem);
    ske_queue_init(mem, max, cap);
    const ske_queue_hdr_t *q = mem;
    CHECK_EQ_U(q->max_size, max);
    CHECK_EQ_U(q->capacity, cap);
    CHECK_EQ_U(atomic_load(&q->head), 0);
    CHECK_EQ_U(atomic_load(&q->tail), 0);
    CHECK_EQ_U(atomic_load(&q->overflows), 0);

    uint32_t tail = 0;
    CHECK_EQ_U(ske_queue_count(mem, cap, tail), 0);
    char m[16];
    for (uint32_t i = 0; i < cap; i++) {
        uint32_t len = make_msg(i, m, max);
        CHECK(ske_queue_push(mem, max, cap, tail, m, len, (int64_t)i * 10));
        CHECK_EQ_U(ske_queue_count(mem, cap, tail), i + 1);
    }
    /* Full: refused, nothing overwritten. */
    CHECK(!ske_queue_push(mem, max, cap, tail, "overflow", 8, 999));
    CHECK_EQ_U(ske_queue_count(mem, cap, tail), cap);
    CHECK_EQ_U(atomic_load(&q->head), cap);

    /* Peek does not consume; the consumer advances its own tail. */
    check_peek(mem, max, cap, tail, 0);
    check_peek(mem, max, cap, tail, 0);
    for (uint32_t i = 0; i < 2; i++, tail++)
        check_peek(mem, max, cap, tail, i);
    CHECK_EQ_U(ske_queue_count(mem, cap, tail), cap - 2);

    /* Two slots free again: reused in order, FIFO preserved across the ring's end. */
    for (uint32_t i = cap; i < cap + 2; i++) {
        uint32_t len = make_msg(i, m, max);
        CHECK(ske_queue_push(mem, max, cap, tail, m, len, (int64_t)i * 10));
    }
    CHECK(!ske_queue_push(mem, max, cap, tail, "overflow", 8, 999));
    for (uint32_t i = 2; i < cap + 2; i++, tail++)
        check_peek(mem, max, cap, tail, i);
    CHECK_EQ_U(ske_queue_count(mem, cap, tail), 0);
    free(mem);
}

static void test_queue_length_clamped(void)
{
    const uint32_t max = 8, cap = 2;
    void *mem = port_mem(ske_queue_map_size(max, cap));
    REQUIRE(mem);
    ske_queue_init(mem, max, cap);
    uint8_t *buf = malloc(max);
    REQUIRE(buf);
    uint32_t len = 0;
    int64_t t = 0;
    /* Oversize push is cut to the slot. */
    CHECK(ske_queue_push(mem, max, cap, 0, "0123456789abcdef", 16, 1));
    ske_queue_peek(mem, max, cap, 0, buf, &len, &t);
    CHECK_EQ_U(len, max);
    CHECK(memcmp(buf, "01234567", 8) == 0);
    /* A corrupted slot length never makes the consumer copy more than max_size. */
    queue_slot(mem, max, 0)->len = UINT32_MAX;
    ske_queue_peek(mem, max, cap, 0, buf, &len, &t);
    CHECK_EQ_U(len, max);
    free(buf);
    free(mem);
}

static void test_queue_indices_wrap(void)
{
    const uint32_t max = 16, cap = 8;
    void *mem = port_mem(ske_queue_map_size(max, cap));
    REQUIRE(mem);
    ske_queue_init(mem, max, cap);
    ske_queue_hdr_t *q = mem;
    /* 2^32 - 3 messages have gone through: head and tail wrap within the next few. */
    uint32_t tail = UINT32_MAX - 2u;
    atomic_store(&q->head, tail);
    CHECK_EQ_U(ske_queue_count(mem, cap, tail), 0);

    char m[16];
    for (uint32_t i = 0; i < cap; i++) {
        uint32_t len = make_msg(i, m, max);
        CHECK(ske_queue_push(mem, max, cap, tail, m, len, (int64_t)i * 10));
        CHECK_EQ_U(ske_queue_count(mem, cap, tail), i + 1);
    }
    CHECK_EQ_U(atomic_load(&q->head), cap - 3u); /* wrapped past 0 */
    CHECK(!ske_queue_push(mem, max, cap, tail, "overflow", 8, 999));
    for (uint32_t i = 0; i < cap; i++, tail++) {
        CHECK_EQ_U(ske_queue_count(mem, cap, tail), cap - i);
        check_peek(mem, max, cap, tail, i);
    }
    CHECK_EQ_U(tail, cap - 3u);
    CHECK_EQ_U(ske_queue_count(mem, cap, tail), 0);
    free(mem);
}

static void test_queue_inconsistent_indices(void)
{
    const uint32_t max = 8, cap = 4;
    void *mem = port_mem(ske_queue_map_size(max, cap));
    REQUIRE(mem);
    ske_queue_init(mem, max, cap);
    ske_queue_hdr_t *q = mem;
    /* The consumer's tail lives in memory the consumer writes: it may be anything. */
    atomic_store(&q->head, 100);
    CHECK_EQ_U(ske_queue_count(mem, cap, 100 - cap), cap); /* full is consistent */
    CHECK_EQ_U(ske_queue_count(mem, cap, 100 - cap - 1), UINT32_MAX); /* more than capacity */
    CHECK_EQ_U(ske_queue_count(mem, cap, 101), UINT32_MAX); /* tail ahead of head */
    CHECK_EQ_U(ske_queue_count(mem, cap, 100 + (UINT32_MAX / 2)), UINT32_MAX);
    CHECK_EQ_U(ske_queue_count(mem, cap, 0), UINT32_MAX);
    /* Near the wrap: head just past 0, tail just below: consistent. */
    atomic_store(&q->head, 1);
    CHECK_EQ_U(ske_queue_count(mem, cap, UINT32_MAX), 2);
    CHECK_EQ_U(ske_queue_count(mem, cap, 2), UINT32_MAX);
    /* The producer refuses to push against an inconsistent tail. */
    atomic_store(&q->head, 100);
    CHECK(!ske_queue_push(mem, max, cap, 101, "x", 1, 0));
    CHECK(!ske_queue_push(mem, max, cap, 90, "x", 1, 0));
    CHECK_EQ_U(atomic_load(&q->head), 100);
    free(mem);
}

/* ---- regressions: defects found and fixed, checked on every run ------------------------ */

/* With a capacity that does not divide 2^32, `head % capacity` jumps when head wraps: the
 * message at index UINT32_MAX and the one at index 0 land in the same slot, and the second
 * overwrites the first while it is still queued. */
static void defect_queue_wrap_with_odd_capacity(void)
{
    const uint32_t max = 8, cap = 3;
    void *mem = port_mem(ske_queue_map_size(max, cap));
    REQUIRE(mem);
    ske_queue_init(mem, max, cap);
    ske_queue_hdr_t *q = mem;
    uint32_t tail = UINT32_MAX - 1u;
    atomic_store(&q->head, tail);
    char m[16];
    for (uint32_t i = 0; i < cap; i++) {
        uint32_t len = make_msg(i, m, max);
        CHECK(ske_queue_push(mem, max, cap, tail, m, len, (int64_t)i * 10));
    }
    for (uint32_t i = 0; i < cap; i++, tail++)
        check_peek(mem, max, cap, tail, i);
    free(mem);
}

int main(int argc, char **argv)
{
    RUN(defect_queue_wrap_with_odd_capacity);
    RUN(test_layout);
    RUN(test_map_sizes_are_page_rounded);
    RUN(test_sampling_empty);
    RUN(test_sampling_round_trip);
    RUN(test_sampling_latest_wins);
    RUN(test_sampling_length_clamped);
    RUN(test_sampling_writer_stopped_mid_write);
    RUN(test_sampling_sequence_wraps);
    RUN(test_queue_fill_and_fifo);
    RUN(test_queue_length_clamped);
    RUN(test_queue_indices_wrap);
    RUN(test_queue_inconsistent_indices);
    return ske_test_result();
}
