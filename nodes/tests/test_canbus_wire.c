/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the CAN wire model: arbitration, timing, error confinement, faults, load. */
#include "canbus__wire.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "canbus_test.h"

/* The worst-case frame length formula of Davis et al., Controller Area Network
 * schedulability analysis, 2007, written out again independently of proto.h. */
static uint32_t formula_bits(int ext, uint32_t s)
{
    uint32_t g = ext ? 54 : 34;
    return g + 8 * s + 13 + (g + 8 * s - 1) / 4;
}

static const uint8_t payload[8] = {1, 2, 3, 4, 5, 6, 7, 8};

static void submit(canbus_wire_t *w, int64_t t, uint32_t id, uint8_t flags, uint8_t len,
                   uint8_t client)
{
    CHECK_EQ(canbus_wire_submit(w, t, id, flags, len, payload, client), 0);
}

/* Events of one kind, in order. */
static size_t events(const canbus_wire_t *w, uint8_t kind, const canbus_wire_ev_t **out,
                     size_t max)
{
    size_t n = 0;
    for (size_t i = w->ev_head; i < w->n_ev; i++)
        if (w->ev[i].kind == kind && n < max)
            out[n++] = &w->ev[i];
    return n;
}

static void test_frame_bits(void)
{
    /* Hand-computed anchors, then every length both ways. */
    CHECK_EQ(formula_bits(0, 0), 55);
    CHECK_EQ(formula_bits(0, 8), 135);
    CHECK_EQ(formula_bits(1, 0), 80);
    CHECK_EQ(formula_bits(1, 8), 160);
    for (uint8_t s = 0; s <= 8; s++) {
        CHECK_EQ(canbus_frame_bits(0, s), formula_bits(0, s));
        CHECK_EQ(canbus_frame_bits(1, s), formula_bits(1, s));
        CHECK_EQ(canbus_wire_frame_bits(0, s), formula_bits(0, s));
        CHECK_EQ(canbus_wire_frame_bits(CANBUS_FRAME_EFF, s), formula_bits(1, s));
        /* A remote frame has no data field whatever its DLC. */
        CHECK_EQ(canbus_wire_frame_bits(CANBUS_FRAME_RTR, s), formula_bits(0, 0));
    }
    /* On the wire: one frame alone, at three bit rates, each length and format. */
    const uint32_t rates[] = {1000000, 125000, 300000};
    for (size_t r = 0; r < 3; r++) {
        for (int ext = 0; ext <= 1; ext++) {
            for (uint8_t s = 0; s <= 8; s++) {
                canbus_wire_t w;
                CHECK_EQ(canbus_wire_init(&w, rates[r], 0), 0);
                canbus_wire_attach(&w, 0, true);
                canbus_wire_attach(&w, 1, true);
                int64_t t0 = 7000000; /* a multiple of every bit time above */
                submit(&w, t0, ext ? 0x1234567 : 0x123, ext ? CANBUS_FRAME_EFF : 0, s, 0);
                CHECK_EQ(canbus_wire_run(&w, 1000000000), 0);
                const canbus_wire_ev_t *e[2];
                CHECK_EQ(events(&w, CANBUS_EV_TX, e, 2), 1);
                uint64_t bits = formula_bits(ext, s);
                CHECK_EQ(e[0]->start_ns, t0);
                /* Exact integer ns: floor(bits * 1e9 / rate) past a bit boundary. */
                uint64_t b0 = (uint64_t)t0 * rates[r] / 1000000000u;
                CHECK_EQ(e[0]->end_ns, (int64_t)((b0 + bits) * 1000000000ull / rates[r]));
                CHECK_EQ(e[0]->len, s);
                CHECK(memcmp(e[0]->data, payload, s) == 0);
                canbus_wire_fini(&w);
            }
        }
    }
}

static void test_time_conversion(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 300000, 0), 0);
    /* 3333.33 ns per bit: bit 1 starts at 3333 ns; a request at 3333 ns gets bit 1. */
    CHECK_EQ(canbus_wire_bit_ns(&w, 1), 3333);
    CHECK_EQ(canbus_wire_bit_ns(&w, 3), 10000);
    CHECK_EQ(canbus_wire_bit_ceil(&w, 3333), 1);
    CHECK_EQ(canbus_wire_bit_ceil(&w, 3334), 2);
    CHECK_EQ(canbus_wire_bit_ceil(&w, 0), 0);
    /* No drift or overflow over a long run: 10^5 s. */
    int64_t long_ns = 100000ll * 1000000000ll;
    CHECK_EQ(canbus_wire_bit_ceil(&w, long_ns), 100000ll * 300000ll);
    CHECK_EQ(canbus_wire_bit_ns(&w, 100000ull * 300000ull + 1), long_ns + 3333);
    canbus_wire_fini(&w);
    CHECK(canbus_wire_init(&w, 10, 0) != 0);
}

static void test_arbitration(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 4; c++)
        canbus_wire_attach(&w, c, true);
    /* All requested at t = 0, submitted in a scrambled order. */
    submit(&w, 0, 0x200, 0, 1, 0);                       /* 6th */
    submit(&w, 0, 0x100, 0, 1, 2);                       /* 3rd: same id, client 2 */
    submit(&w, 0, 0x100u << 18, CANBUS_FRAME_EFF, 1, 0); /* 5th: base 0x100 extended */
    submit(&w, 0, 0x100, 0, 2, 1);                       /* 1st: client 1, first */
    submit(&w, 0, 0x100, CANBUS_FRAME_RTR, 0, 0);        /* 4th: remote loses to data */
    submit(&w, 0, 0x100, 0, 3, 1);                       /* 2nd: client 1, second */
    submit(&w, 0, (0x0FFu << 18) | 0x3FFFF, CANBUS_FRAME_EFF, 0, 3); /* 0th: base 0x0FF */
    CHECK_EQ(canbus_wire_run(&w, 10000000), 0);
    const canbus_wire_ev_t *e[8];
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 8), 7);
    CHECK_EQ(e[0]->client, 3);
    CHECK_EQ(e[1]->client, 1);
    CHECK_EQ(e[1]->len, 2);
    CHECK_EQ(e[2]->client, 1);
    CHECK_EQ(e[2]->len, 3);
    CHECK_EQ(e[3]->client, 2);
    CHECK_EQ(e[4]->client, 0);
    CHECK(e[4]->flags & CANBUS_FRAME_RTR);
    CHECK(e[5]->flags & CANBUS_FRAME_EFF);
    CHECK_EQ(e[6]->id, 0x200);
    /* Back to back: each starts when the previous one (interframe space included) ends. */
    CHECK_EQ(e[0]->start_ns, 0);
    for (int i = 1; i < 7; i++)
        CHECK_EQ(e[i]->start_ns, e[i - 1]->end_ns);
    CHECK_EQ(e[0]->end_ns, formula_bits(1, 0) * 1000);
    /* The key orders the wire bits: base first, standard before extended on a tie. */
    CHECK(canbus_wire_arb_key(0x100, 0) < canbus_wire_arb_key(0x100u << 18, CANBUS_FRAME_EFF));
    CHECK(canbus_wire_arb_key(0x100, CANBUS_FRAME_RTR) <
          canbus_wire_arb_key(0x100u << 18, CANBUS_FRAME_EFF));
    CHECK(canbus_wire_arb_key(0x0FFu << 18 | 0x3FFFF, CANBUS_FRAME_EFF) <
          canbus_wire_arb_key(0x100, 0));
    CHECK(canbus_wire_arb_key(5, CANBUS_FRAME_EFF) < canbus_wire_arb_key(6, CANBUS_FRAME_EFF));
    canbus_wire_fini(&w);

    /* A frame requested while the wire is busy waits, then wins over an older, higher id. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    submit(&w, 0, 0x300, 0, 8, 0);      /* 0 .. 135 us */
    submit(&w, 10000, 0x500, 0, 8, 1);  /* waits */
    submit(&w, 100000, 0x050, 0, 8, 2); /* requested later, lower id */
    submit(&w, 500000, 0x010, 0, 8, 2); /* after an idle gap */
    CHECK_EQ(canbus_wire_run(&w, 1000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 8), 4);
    CHECK_EQ(e[1]->id, 0x050);
    CHECK_EQ(e[1]->start_ns, 135000);
    CHECK_EQ(e[2]->id, 0x500);
    CHECK_EQ(e[2]->start_ns, 270000);
    CHECK_EQ(e[3]->start_ns, 500000);
    canbus_wire_fini(&w);

    /* --gap-bits adds idle bits after each frame. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 3), 0);
    submit(&w, 0, 0x1, 0, 8, 0);
    submit(&w, 0, 0x2, 0, 8, 0);
    CHECK_EQ(canbus_wire_run(&w, 1000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 8), 2);
    CHECK_EQ(e[1]->start_ns, 138000);
    canbus_wire_fini(&w);
}

static void test_quantum_boundary(void)
{
    canbus_wire_t w;
    const canbus_wire_ev_t *e[4];
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    /* Starts before the end of the run, ends after it. */
    submit(&w, 4950000, 0x10, 0, 8, 0);
    submit(&w, 5000000, 0x20, 0, 8, 1); /* requested at the end: not started yet */
    CHECK_EQ(canbus_wire_run(&w, 5000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 4), 1);
    CHECK_EQ(e[0]->start_ns, 4950000);
    CHECK_EQ(e[0]->end_ns, 5085000);
    CHECK_EQ(canbus_wire_run(&w, 10000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 4), 2);
    CHECK_EQ(e[1]->start_ns, 5085000);
    canbus_wire_fini(&w);
}

static void test_error_frame(void)
{
    canbus_wire_t w;
    const canbus_wire_ev_t *e[8];
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 3; c++)
        canbus_wire_attach(&w, c, true);
    canbus_fault_t f = {.kind = CANBUS_FAULT_CORRUPT, .target = CANBUS_ANY, .match_id = 0x100,
                        .until_ns = INT64_MAX, .limit = 1};
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 0, 0x100, 0, 8, 1);
    CHECK_EQ(canbus_wire_run(&w, 1000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_ERROR, e, 8), 1);
    /* Up to the ACK delimiter (135 - 10), 20-bit error frame, 3-bit interframe space. */
    CHECK_EQ(e[0]->start_ns, 0);
    CHECK_EQ(e[0]->end_ns, (135 - 10 + 20 + 3) * 1000);
    CHECK_EQ(e[0]->tec, 8);
    CHECK_EQ(e[0]->state, CANBUS_ERR_ACTIVE);
    CHECK_EQ(e[0]->client, 1);
    const canbus_wire_ev_t *tx[2];
    CHECK_EQ(events(&w, CANBUS_EV_TX, tx, 2), 1);
    CHECK_EQ(tx[0]->start_ns, e[0]->end_ns); /* automatic retransmission */
    CHECK_EQ(tx[0]->tec, 7);
    CHECK_EQ(w.ctl[1].tec, 7);
    CHECK_EQ(w.ctl[0].rec, 0); /* +1 for the error, -1 for the good frame */
    CHECK_EQ(w.ctl[2].rec, 0);
    CHECK_EQ(w.error_frames, 1);
    CHECK_EQ(w.busy_bits, 148 + 135);
    canbus_wire_fini(&w);
}

static void test_bus_off(void)
{
    canbus_wire_t w;
    static const canbus_wire_ev_t *e[64];
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 3; c++)
        canbus_wire_attach(&w, c, true);
    canbus_fault_t f = {.kind = CANBUS_FAULT_CORRUPT, .target = 0, .match_id = CANBUS_ANY_ID,
                        .until_ns = INT64_MAX};
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 0, 0x100, 0, 8, 0);
    submit(&w, 0, 0x101, 0, 8, 0);      /* queued behind it: lost at bus-off */
    submit(&w, 0, 0x200, 0, 8, 1);      /* loses every arbitration until then */
    submit(&w, 20000000, 0x100, 0, 8, 0); /* after bus-off: dropped */
    CHECK_EQ(canbus_wire_run(&w, 50000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_ERROR, e, 64), 32);
    for (int i = 0; i < 32; i++) {
        CHECK_EQ(e[i]->tec, 8 * (i + 1));
        CHECK_EQ(e[i]->id, 0x100);
        uint8_t want = i < 15   ? CANBUS_ERR_ACTIVE
                       : i < 31 ? CANBUS_ERR_PASSIVE
                                : CANBUS_ERR_BUS_OFF;
        CHECK_EQ(e[i]->state, want);
        if (i)
            CHECK_EQ(e[i]->start_ns, e[i - 1]->end_ns);
    }
    CHECK_EQ(w.ctl[1].rec, 32);     /* it sent the good frame after */
    CHECK_EQ(w.ctl[2].rec, 32 - 1); /* it received it */
    int64_t off_ns = e[31]->end_ns;
    CHECK_EQ(events(&w, CANBUS_EV_BUS_OFF, e, 64), 1);
    CHECK_EQ(e[0]->client, 0);
    CHECK_EQ(e[0]->end_ns, off_ns);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 64), 1);
    CHECK_EQ(e[0]->id, 0x200);
    CHECK_EQ(e[0]->start_ns, off_ns);
    /* The failing frame and the one queued behind it at bus-off, the later one at its time. */
    CHECK_EQ(events(&w, CANBUS_EV_DROP, e, 64), 3);
    CHECK_EQ(e[0]->id + e[1]->id, 0x100 + 0x101);
    CHECK_EQ(e[0]->end_ns, off_ns);
    CHECK_EQ(e[1]->end_ns, off_ns);
    CHECK_EQ(e[0]->reason, CANBUS_DROP_BUS_OFF);
    CHECK_EQ(e[2]->end_ns, 20000000);
    CHECK_EQ(canbus_wire_state(&w, 0), CANBUS_ERR_BUS_OFF);
    CHECK_EQ(canbus_wire_state(&w, 1), CANBUS_ERR_ACTIVE);
    CHECK_EQ(w.bus_off_events, 1);
    CHECK_EQ(w.dropped, 3);
    canbus_wire_fini(&w);
}

static void test_recovery_and_forced_bus_off(void)
{
    canbus_wire_t w;
    const canbus_wire_ev_t *e[8];
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    canbus_wire_attach(&w, 0, true);
    canbus_wire_attach(&w, 1, true);
    canbus_fault_t f = {.kind = CANBUS_FAULT_BUS_OFF, .target = 1, .match_id = CANBUS_ANY_ID,
                        .from_ns = 1000000, .until_ns = INT64_MAX, .recover = true};
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 1500000, 0x10, 0, 0, 1); /* during bus-off: dropped */
    submit(&w, 3000000, 0x11, 0, 0, 1); /* after recovery: sent */
    CHECK_EQ(canbus_wire_run(&w, 5000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_BUS_OFF, e, 8), 1);
    CHECK_EQ(e[0]->end_ns, 1000000);
    CHECK_EQ(e[0]->reason, 1);
    CHECK_EQ(events(&w, CANBUS_EV_BUS_ON, e, 8), 1);
    CHECK_EQ(e[0]->end_ns, 1000000 + 128 * 11 * 1000);
    CHECK_EQ(events(&w, CANBUS_EV_DROP, e, 8), 1);
    CHECK_EQ(e[0]->id, 0x10);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 8), 1);
    CHECK_EQ(e[0]->id, 0x11);
    CHECK_EQ(e[0]->start_ns, 3000000);
    CHECK_EQ(w.ctl[1].tec, 0);
    canbus_wire_fini(&w);

    /* Without arming, bus-off is for the rest of the run. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    f.recover = false;
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 3000000, 0x11, 0, 0, 1);
    CHECK_EQ(canbus_wire_run(&w, 5000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_BUS_ON, e, 8), 0);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 8), 0);
    canbus_wire_fini(&w);
}

static void test_drop_delay_babble(void)
{
    canbus_wire_t w;
    const canbus_wire_ev_t *e[64];
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    canbus_fault_t drop = {.kind = CANBUS_FAULT_DROP, .target = CANBUS_ANY, .match_id = 0x42,
                           .until_ns = INT64_MAX, .limit = 1};
    canbus_fault_t delay = {.kind = CANBUS_FAULT_DELAY, .target = 1, .match_id = CANBUS_ANY_ID,
                            .from_ns = 0, .until_ns = 1000000, .delay_ns = 2000000};
    CHECK_EQ(canbus_wire_add_fault(&w, &drop), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &delay), 0);
    submit(&w, 0, 0x42, 0, 1, 0);       /* dropped (first match) */
    submit(&w, 100000, 0x42, 0, 1, 0);  /* sent */
    submit(&w, 500000, 0x7, 0, 1, 1);   /* delayed to 2.5 ms */
    submit(&w, 1500000, 0x8, 0, 1, 1);  /* outside the delay window */
    CHECK_EQ(canbus_wire_run(&w, 10000000), 0);
    CHECK_EQ(events(&w, CANBUS_EV_DROP, e, 64), 1);
    CHECK_EQ(e[0]->reason, CANBUS_DROP_FAULT);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 64), 3);
    CHECK_EQ(e[0]->id, 0x42);
    CHECK_EQ(e[0]->start_ns, 100000);
    CHECK_EQ(e[1]->id, 0x8);
    CHECK_EQ(e[1]->start_ns, 1500000);
    CHECK_EQ(e[2]->id, 0x7);
    CHECK_EQ(e[2]->start_ns, 2500000);
    canbus_wire_fini(&w);

    /* A babbler holds the wire with identifier 0 for its window: others wait it out. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    canbus_fault_t bab = {.kind = CANBUS_FAULT_BABBLE, .target = CANBUS_ANY,
                          .match_id = CANBUS_ANY_ID, .from_ns = 1000000, .until_ns = 2000000,
                          .babble_id = 0, .babble_len = 8};
    CHECK_EQ(canbus_wire_add_fault(&w, &bab), 0);
    submit(&w, 1000000, 0x10, 0, 8, 0);
    CHECK_EQ(canbus_wire_run(&w, 5000000), 0);
    size_t n = events(&w, CANBUS_EV_TX, e, 64);
    CHECK_EQ(n, 9); /* 8 babble frames start in [1 ms, 2 ms), 135 us each, then ours */
    for (size_t i = 0; i + 1 < n; i++) {
        CHECK_EQ(e[i]->id, 0);
        CHECK_EQ(e[i]->client, CANBUS_ANY);
        CHECK_EQ(e[i]->start_ns, 1000000 + (int64_t)i * 135000);
    }
    CHECK_EQ(e[n - 1]->id, 0x10);
    CHECK_EQ(e[n - 1]->start_ns, 1000000 + 8 * 135000);
    canbus_wire_fini(&w);
}

static void test_load(void)
{
    canbus_wire_t w;
    double load, max1;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (int i = 0; i < 10; i++)
        submit(&w, 0, 0x100, 0, 8, 0); /* 1350 bits in the first second */
    submit(&w, 1999900000, 0x100, 0, 8, 0); /* 100 bits in second 1, 35 in second 2 */
    CHECK_EQ(canbus_wire_run(&w, 3000000000), 0);
    CHECK_EQ(w.busy_bits, 11 * 135);
    canbus_wire_load(&w, 3000000000, &load, &max1);
    CHECK_NEAR(load, 1485.0 / 3e6, 1e-9);
    CHECK_NEAR(max1, 1350.0 / 1e6, 1e-9);
    canbus_wire_load(&w, 500000000, &load, &max1); /* no complete window: overall */
    CHECK_NEAR(max1, load, 1e-9);
    canbus_wire_fini(&w);

    /* A saturated wire is loaded 100 %. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (int i = 0; i < 8000; i++)
        submit(&w, 0, (uint32_t)(i % 0x7FF), 0, 8, (uint8_t)(i % 4));
    CHECK_EQ(canbus_wire_run(&w, 1000000000), 0);
    canbus_wire_load(&w, 1000000000, &load, &max1);
    CHECK(load > 0.9999);
    CHECK_EQ(w.frames, 1000000 / 135 + 1); /* the last one starts before 1 s */
    canbus_wire_fini(&w);
}

static void test_pending_limit(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint32_t i = 0; i < CANBUS_WIRE_MAX_PENDING; i++)
        CHECK_EQ(canbus_wire_submit(&w, 0, 0x10, 0, 0, NULL, 0), 0);
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x10, 0, 0, NULL, 0), CANBUS_WIRE_EFULL);
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x10, 0, 0, NULL, 1), 0); /* others are not affected */
    CHECK_EQ(canbus_wire_run(&w, 55000), 0);                      /* one frame goes */
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x10, 0, 0, NULL, 0), 0);
    CHECK_EQ(canbus_wire_submit(&w, 0, 0x800, 0, 0, NULL, 0), CANBUS_WIRE_EINVAL);
    CHECK_EQ(canbus_wire_submit(&w, 0, 1, 0, 9, NULL, 0), CANBUS_WIRE_EINVAL);
    canbus_wire_fini(&w);
}

static void test_fault_parse(void)
{
    canbus_fault_t f;
    char name[33], err[128];
    CHECK_EQ(canbus_fault_parse("corrupt:client=2,id=0x100,from=10ms,until=1s,count=40", &f,
                                name, sizeof name, err, sizeof err),
             0);
    CHECK_EQ(f.kind, CANBUS_FAULT_CORRUPT);
    CHECK_EQ(f.target, 2);
    CHECK_EQ(f.match_id, 0x100);
    CHECK_EQ(f.from_ns, 10000000);
    CHECK_EQ(f.until_ns, 1000000000);
    CHECK_EQ(f.limit, 40);
    CHECK_EQ(name[0], '\0');
    CHECK_EQ(canbus_fault_parse("bus_off:client=node2/io,from=1.5s,recover=1", &f, name,
                                sizeof name, err, sizeof err),
             0);
    CHECK_EQ(f.target, CANBUS_NOBODY);
    CHECK(strcmp(name, "node2/io") == 0);
    CHECK_EQ(f.from_ns, 1500000000);
    CHECK(f.recover);
    CHECK_EQ(canbus_fault_parse("babble:id=0x1000,len=8", &f, name, sizeof name, err,
                                sizeof err),
             0);
    CHECK_EQ(f.babble_flags, CANBUS_FRAME_EFF);
    CHECK_EQ(f.match_id, CANBUS_ANY_ID);
    CHECK_EQ(canbus_fault_parse("delay:delay=5ms", &f, name, sizeof name, err, sizeof err), 0);
    CHECK_EQ(f.delay_ns, 5000000);
    CHECK(canbus_fault_parse("melt:client=1", &f, name, sizeof name, err, sizeof err) != 0);
    CHECK(canbus_fault_parse("delay", &f, name, sizeof name, err, sizeof err) != 0);
    CHECK(canbus_fault_parse("drop:from=2s,until=1s", &f, name, sizeof name, err, sizeof err));
    CHECK(canbus_fault_parse("drop:id=0x20000000", &f, name, sizeof name, err, sizeof err));
    CHECK(canbus_fault_parse("drop:bogus=1", &f, name, sizeof name, err, sizeof err));

    struct canbus_rec r = {.type = CANBUS_MSG_FAULT, .flags = CANBUS_FAULT_DELAY, .id = 0x55,
                           .t_ns = 100, .aux = 0, .data = {3, 0xE8, 0x03, 0, 0}};
    CHECK_EQ(canbus_fault_from_rec(&r, &f), 0);
    CHECK_EQ(f.delay_ns, 1000000);
    CHECK_EQ(f.target, 3);
    CHECK_EQ(f.until_ns, INT64_MAX);
    r.flags = CANBUS_FAULT_BABBLE;
    memcpy(r.data, (uint8_t[8]){0xFF, 0x00, 0x01, 0x00, 0x80, 8, 10, 0}, 8);
    CHECK_EQ(canbus_fault_from_rec(&r, &f), 0);
    CHECK_EQ(f.babble_id, 0x100);
    CHECK_EQ(f.babble_flags, CANBUS_FRAME_EFF);
    CHECK_EQ(f.limit, 10);
    r.data[4] = 0; /* 0x100 as an 11-bit id is fine ... */
    CHECK_EQ(canbus_fault_from_rec(&r, &f), 0);
    r.data[3] = 1; /* ... 0x10100 is not */
    CHECK(canbus_fault_from_rec(&r, &f) != 0);
    r.flags = 9;
    CHECK(canbus_fault_from_rec(&r, &f) != 0);
    r.flags = CANBUS_FAULT_DROP;
    r.data[0] = 0xFE;
    CHECK(canbus_fault_from_rec(&r, &f) != 0);
}

int main(void)
{
    test_frame_bits();
    test_time_conversion();
    test_arbitration();
    test_quantum_boundary();
    test_error_frame();
    test_bus_off();
    test_recovery_and_forced_bus_off();
    test_drop_delay_babble();
    test_load();
    test_pending_limit();
    test_fault_parse();
    if (unit_failures)
        fprintf(stderr, "test_canbus_wire: %d check(s) failed\n", unit_failures);
    else
        printf("test_canbus_wire: ok\n");
    return unit_failures ? 1 : 0;
}
