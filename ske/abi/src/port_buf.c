/* SPDX-License-Identifier: Apache-2.0 */
/* Port memory operations shared by the SKE and the APEX library: sampling slots and queues. */
#include "ske_abi.h"

#include <errno.h>
#include <linux/futex.h>
#include <string.h>
#include <sys/syscall.h>
#include <unistd.h>

#define SKE_PORT_MAGIC 0x54524f50u /* "PORT" */

static size_t round8(size_t n) { return (n + 7u) & ~(size_t)7u; }

static size_t round_page(size_t n)
{
    const size_t page = 4096u;
    return (n + page - 1u) & ~(page - 1u);
}

size_t ske_slot_stride(uint32_t max_size) { return sizeof(ske_slot_hdr_t) + round8(max_size); }

size_t ske_sampling_map_size(uint32_t max_size)
{
    return round_page(sizeof(ske_sampling_hdr_t) + 2u * ske_slot_stride(max_size));
}

/* Queue slots: a power of two at least the capacity, so that the 32-bit message counters
 * map to the same slot on both sides of their wrap-around. */
static uint32_t queue_slots(uint32_t capacity)
{
    uint32_t n = 1;
    while (n < capacity && n < (1u << 31))
        n <<= 1;
    return n;
}

size_t ske_queue_map_size(uint32_t max_size, uint32_t capacity)
{
    return round_page(sizeof(ske_queue_hdr_t) + (size_t)queue_slots(capacity) * ske_slot_stride(max_size));
}

static ske_slot_hdr_t *slot_at(void *base, size_t hdr, uint32_t max_size, uint32_t i)
{
    return (ske_slot_hdr_t *)((char *)base + hdr + (size_t)i * ske_slot_stride(max_size));
}

void ske_sampling_init(void *mem, uint32_t max_size)
{
    ske_sampling_hdr_t *h = mem;
    memset(mem, 0, ske_sampling_map_size(max_size));
    h->magic = SKE_PORT_MAGIC;
    h->max_size = max_size;
    atomic_store_explicit(&h->seq, 0, memory_order_release);
}

void ske_sampling_write(void *mem, uint32_t max_size, const void *msg, uint32_t len, int64_t t_ns)
{
    ske_sampling_hdr_t *h = mem;
    uint32_t next = atomic_load_explicit(&h->seq, memory_order_relaxed) + 1u;
    if (next == 0)
        next = 2; /* keep 0 for "never written"; keep the slot parity alternating */
    ske_slot_hdr_t *s = slot_at(mem, sizeof(*h), max_size, next & 1u);
    if (len > max_size)
        len = max_size;
    s->t_ns = t_ns;
    s->len = len;
    s->seq = next;
    memcpy(s + 1, msg, len);
    atomic_store_explicit(&h->seq, next, memory_order_release);
}

bool ske_sampling_read(const void *mem, uint32_t max_size, void *msg, uint32_t *len, int64_t *t_ns)
{
    uint32_t seq;
    return ske_sampling_read_seq(mem, max_size, msg, len, t_ns, &seq);
}

bool ske_sampling_read_seq(const void *mem, uint32_t max_size, void *msg, uint32_t *len,
                           int64_t *t_ns, uint32_t *seq_out)
{
    const ske_sampling_hdr_t *h = mem;
    /* Partitions never run at the same time, but a writer stopped late after an overrun
     * might still be writing: if a new message was published while we copied, copy again. */
    for (int tries = 0;; tries++) {
        uint32_t seq = atomic_load_explicit(&h->seq, memory_order_acquire);
        if (seq == 0)
            return false;
        const ske_slot_hdr_t *s = slot_at((void *)mem, sizeof(*h), max_size, seq & 1u);
        uint32_t n = *(const volatile uint32_t *)&s->len; /* read once */
        if (n > max_size)
            n = max_size;
        int64_t t = *(const volatile int64_t *)&s->t_ns;
        memcpy(msg, s + 1, n);
        atomic_thread_fence(memory_order_acquire);
        if (atomic_load_explicit(&h->seq, memory_order_relaxed) == seq || tries >= 3) {
            *len = n;
            *t_ns = t;
            *seq_out = seq;
            return true;
        }
    }
}

bool ske_sampling_latest(const void *mem, uint32_t max_size, uint32_t *seq_out, int64_t *t_ns)
{
    const ske_sampling_hdr_t *h = mem;
    uint32_t seq = atomic_load_explicit(&h->seq, memory_order_acquire);
    if (seq == 0)
        return false;
    const ske_slot_hdr_t *s = slot_at((void *)mem, sizeof(*h), max_size, seq & 1u);
    *t_ns = *(const volatile int64_t *)&s->t_ns;
    *seq_out = seq;
    return true;
}

void *ske_sampling_latest_msg(void *mem, uint32_t max_size, uint32_t *len, uint32_t *seq)
{
    ske_sampling_hdr_t *h = mem;
    uint32_t n = atomic_load_explicit(&h->seq, memory_order_acquire);
    if (n == 0)
        return NULL;
    ske_slot_hdr_t *s = slot_at(mem, sizeof(*h), max_size, n & 1u);
    uint32_t l = *(volatile uint32_t *)&s->len; /* read once: the writer may have lied */
    *len = l < max_size ? l : max_size;
    *seq = n;
    return s + 1;
}

void ske_queue_init(void *mem, uint32_t max_size, uint32_t capacity)
{
    ske_queue_hdr_t *q = mem;
    memset(mem, 0, ske_queue_map_size(max_size, capacity));
    q->magic = SKE_PORT_MAGIC;
    q->max_size = max_size;
    q->capacity = capacity;
}

uint32_t ske_queue_count(const void *mem, uint32_t capacity, uint32_t tail)
{
    const ske_queue_hdr_t *q = mem;
    uint32_t n = atomic_load_explicit(&q->head, memory_order_acquire) - tail;
    return n <= capacity ? n : UINT32_MAX;
}

bool ske_queue_push(void *mem, uint32_t max_size, uint32_t capacity, uint32_t tail,
                    const void *msg, uint32_t len, int64_t t_ns)
{
    ske_queue_hdr_t *q = mem;
    uint32_t head = atomic_load_explicit(&q->head, memory_order_relaxed);
    if (head - tail >= capacity)
        return false;
    ske_slot_hdr_t *s = slot_at(mem, sizeof(*q), max_size, head & (queue_slots(capacity) - 1u));
    if (len > max_size)
        len = max_size;
    s->t_ns = t_ns;
    s->len = len;
    s->seq = head;
    memcpy(s + 1, msg, len);
    atomic_store_explicit(&q->head, head + 1u, memory_order_release);
    return true;
}

void ske_queue_peek(const void *mem, uint32_t max_size, uint32_t capacity, uint32_t tail,
                    void *msg, uint32_t *len, int64_t *t_ns)
{
    const ske_slot_hdr_t *s = slot_at((void *)mem, sizeof(ske_queue_hdr_t), max_size,
                                      tail & (queue_slots(capacity) - 1u));
    uint32_t n = *(const volatile uint32_t *)&s->len; /* read once: the bound is checked */
    if (n > max_size)
        n = max_size;
    *t_ns = *(const volatile int64_t *)&s->t_ns;
    memcpy(msg, s + 1, n);
    *len = n;
}

int64_t ske_queue_head_time(const void *mem, uint32_t max_size, uint32_t capacity, uint32_t tail)
{
    const ske_slot_hdr_t *s = slot_at((void *)mem, sizeof(ske_queue_hdr_t), max_size,
                                      tail & (queue_slots(capacity) - 1u));
    return *(const volatile int64_t *)&s->t_ns;
}

int64_t ske_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

int ske_futex_wait(_Atomic uint32_t *word, uint32_t expected, const struct timespec *rel)
{
    long r = syscall(SYS_futex, (uint32_t *)word, FUTEX_WAIT, expected, rel, NULL, 0);
    return r == 0 ? 0 : -errno;
}

int ske_futex_wake(_Atomic uint32_t *word)
{
    long r = syscall(SYS_futex, (uint32_t *)word, FUTEX_WAKE, 1, NULL, NULL, 0);
    return r >= 0 ? 0 : -errno;
}
