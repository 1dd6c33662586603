/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the bus's fault injector (faultinject/can/): the common grammar and the older
 * forms, spells, the applied/cleared bookkeeping, and each class acting on the wire model. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "canbus__wire.h"
#include "canbus_test.h"

#define MS 1000000LL

static const uint8_t payload[8] = {1, 2, 3, 4, 5, 6, 7, 8};

static void submit(canbus_wire_t *w, int64_t t, uint32_t id, uint8_t client)
{
    CHECK_EQ(canbus_wire_submit(w, t, id, 0, 8, payload, client), 0);
}

/* Events of one kind since the start, in order. */
static size_t events(const canbus_wire_t *w, uint8_t kind, const canbus_wire_ev_t **out,
                     size_t max)
{
    size_t n = 0;
    for (size_t i = w->ev_head; i < w->n_ev; i++)
        if (w->ev[i].kind == kind && n < max)
            out[n++] = &w->ev[i];
    return n;
}

static int parse(const char *spec, canbus_fault_t *f, char *name)
{
    char err[200] = "";
    int rc = canbus_fault_parse(spec, f, name, CANBUS_NAME_LEN + 1, err, sizeof err);
    if (rc && getenv("VERBOSE"))
        fprintf(stderr, "%s: %s\n", spec, err);
    return rc;
}

static void test_parse_common_grammar(void)
{
    canbus_fault_t f;
    char name[CANBUS_NAME_LEN + 1];
    CHECK_EQ(parse("can_drop:fid=d1,at=1s,until=2s,client=node2/io,id=0x123,count=3", &f, name), 0);
    CHECK_EQ(f.kind, CANBUS_FAULT_DROP);
    CHECK(strcmp(f.fid, "d1") == 0);
    CHECK(strcmp(name, "node2/io") == 0);
    CHECK_EQ(f.target, CANBUS_NOBODY);
    CHECK_EQ(f.match_id, 0x123);
    CHECK_EQ(f.from_ns, 1000 * MS);
    CHECK_EQ(f.until_ns, 2000 * MS);
    CHECK_EQ(f.limit, 3);
    CHECK_EQ(f.period_ns, 0);
    CHECK_EQ(parse("rx_drop:fid=r,at=10ms,period=100ms,on=20ms,client=3,id=0x8", &f, name), 0);
    CHECK_EQ(f.kind, CANBUS_FAULT_RX_DROP);
    CHECK_EQ(f.target, 3);
    CHECK_EQ(f.period_ns, 100 * MS);
    CHECK_EQ(f.on_ns, 20 * MS);
    CHECK_EQ(f.until_ns, INT64_MAX);
    CHECK_EQ(parse("can_duplicate:fid=x,at=0", &f, name), 0);
    CHECK_EQ(f.kind, CANBUS_FAULT_DUPLICATE);
    CHECK_EQ(parse("babbling_idiot:fid=b,at=1s,until=3s,id=0x1000,len=8", &f, name), 0);
    CHECK_EQ(f.babble_flags, CANBUS_FRAME_EFF);
    CHECK_EQ(parse("can_delay:fid=y,at=0,delay=2ms", &f, name), 0);
    CHECK_EQ(f.delay_ns, 2 * MS);
    CHECK_EQ(parse("transceiver_cut:fid=c,at=5s,until=6s,client=node3", &f, name), 0);
    CHECK(strcmp(name, "node3") == 0);
    CHECK_EQ(f.kind, CANBUS_FAULT_CUT);
    /* A can_bus_off spell has an end (the controller comes back then); the older form acts
     * once at its start, whatever its window said. */
    CHECK_EQ(parse("can_bus_off:fid=o,at=1s,until=2s,client=1", &f, name), 0);
    CHECK_EQ(f.until_ns, 2000 * MS);
    CHECK_EQ(parse("bus_off:client=1,from=1s,until=2s", &f, name), 0);
    CHECK_EQ(f.until_ns, INT64_MAX);
    CHECK_EQ(f.kind, CANBUS_FAULT_BUS_OFF);
    /* Older forms: no fid (the bus assigns one), no start (0); a fid may still be given. */
    CHECK_EQ(parse("drop:id=0x42", &f, name), 0);
    CHECK_EQ(f.fid[0], '\0');
    CHECK_EQ(f.from_ns, 0);
    CHECK_EQ(parse("corrupt:fid=mine,client=2,from=3ms", &f, name), 0);
    CHECK(strcmp(f.fid, "mine") == 0);
    CHECK_EQ(f.from_ns, 3 * MS);
    CHECK_EQ(f.kind, CANBUS_FAULT_CORRUPT);

    static const char *const bad[] = {
        "can_drop:at=1s",                      /* no fid */
        "can_drop:fid=a",                      /* no at */
        "can_drop:fid=a,at=1s,bogus=1",        /* unknown key */
        "can_delay:fid=a,at=1s",               /* no delay */
        "babbling_idiot:fid=a,at=0",           /* no id to send */
        "transceiver_cut:fid=a,at=0",          /* cuts whom? */
        "transceiver_cut:fid=a,at=0,client=any",
        "can_drop:fid=a,at=0,client=250",      /* no such index */
        "can_drop:fid=a,at=0,id=0x20000000",
        "can_drop:fid=a,at=2s,until=1s",
        "can_melt:fid=a,at=0",
        "melt:client=1",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        if (parse(bad[i], &f, name) == 0) {
            fprintf(stderr, "accepted: %s\n", bad[i]);
            unit_failures++;
        }
}

static void test_records_of_new_kinds(void)
{
    canbus_fault_t f;
    struct canbus_rec r = {.type = CANBUS_MSG_FAULT, .flags = CANBUS_FAULT_RX_DROP, .id = 0x55,
                           .t_ns = 100, .aux = 200, .data = {4, 2, 0}};
    CHECK_EQ(canbus_fault_from_rec(&r, &f), 0);
    CHECK_EQ(f.target, 4);
    CHECK_EQ(f.limit, 2);
    CHECK_EQ(f.until_ns, 200);
    r.flags = CANBUS_FAULT_DUPLICATE;
    CHECK_EQ(canbus_fault_from_rec(&r, &f), 0);
    r.flags = CANBUS_FAULT_CUT;
    CHECK_EQ(canbus_fault_from_rec(&r, &f), 0);
    CHECK_EQ(f.match_id, CANBUS_ANY_ID);
    r.data[0] = CANBUS_ANY; /* cutting everyone is refused */
    CHECK(canbus_fault_from_rec(&r, &f) != 0);
    r.flags = CANBUS_FAULT_KINDS + 1;
    CHECK(canbus_fault_from_rec(&r, &f) != 0);
}

static void test_spells(void)
{
    canbus_fault_t f = {.from_ns = 10, .until_ns = 100, .period_ns = 30, .on_ns = 10};
    CHECK_EQ(canbus_fault_spell(&f, 9), -1);
    CHECK_EQ(canbus_fault_spell(&f, 10), 0);
    CHECK_EQ(canbus_fault_spell(&f, 19), 0);
    CHECK_EQ(canbus_fault_spell(&f, 20), -1);
    CHECK_EQ(canbus_fault_spell(&f, 45), 1);
    CHECK_EQ(canbus_fault_spell(&f, 100), -1);
    CHECK_EQ(canbus_fault_spell_end(&f, 1), 50);
    CHECK_EQ(canbus_fault_next_edge(&f, 0), 10);
    CHECK_EQ(canbus_fault_next_edge(&f, 10), 20);
    CHECK_EQ(canbus_fault_next_edge(&f, 20), 40);
    CHECK_EQ(canbus_fault_next_edge(&f, 95), 100); /* the last spell is cut by until */
    CHECK_EQ(canbus_fault_next_edge(&f, 100), INT64_MAX);
    canbus_fault_t p = {.from_ns = 5, .until_ns = INT64_MAX};
    CHECK_EQ(canbus_fault_next_edge(&p, 5), INT64_MAX);
    CHECK_EQ(canbus_fault_spell_end(&p, 0), INT64_MAX);

    /* applied once per spell; cleared when the spell is seen over */
    f.spell = f.last_spell = -1;
    canbus_fault_note_t n = canbus_fault_hit(&f, 12);
    CHECK(n.applied && !n.cleared);
    n = canbus_fault_hit(&f, 15);
    CHECK(!n.applied && !n.cleared);
    int64_t end;
    uint32_t hits;
    CHECK(!canbus_fault_spell_over(&f, 19, &end, &hits));
    n = canbus_fault_hit(&f, 41); /* the next spell before the first's end was seen */
    CHECK(n.applied && n.cleared);
    CHECK_EQ(n.cleared_spell, 0);
    CHECK_EQ(n.cleared_hits, 2);
    CHECK(canbus_fault_spell_over(&f, 50, &end, &hits));
    CHECK_EQ(end, 50);
    CHECK_EQ(hits, 1);
    CHECK(!canbus_fault_spell_over(&f, 60, &end, &hits));
    n = canbus_fault_hit(&f, 45); /* matched in a spell already written off: no event */
    CHECK(!n.applied && !n.cleared);
}

/* The fault events of the wire: (state, time) in order. */
static size_t fault_events(const canbus_wire_t *w, uint8_t states[], int64_t times[], size_t max)
{
    const canbus_wire_ev_t *e[64];
    size_t n = events(w, CANBUS_EV_FAULT, e, 64);
    for (size_t i = 0; i < n && i < max; i++) {
        states[i] = e[i]->reason;
        times[i] = e[i]->end_ns;
    }
    return n;
}

static void test_intermittent_drop_events(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    canbus_fault_t f;
    char name[CANBUS_NAME_LEN + 1];
    CHECK_EQ(parse("can_drop:fid=d,at=1ms,period=10ms,on=2ms,until=30ms,id=0x42", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    for (int64_t t = 0; t < 30 * MS; t += MS)
        submit(&w, t, 0x42, 0);
    CHECK_EQ(canbus_wire_run(&w, 40 * MS), 0);
    const canbus_wire_ev_t *e[64];
    CHECK_EQ(events(&w, CANBUS_EV_DROP, e, 64), 6); /* 1, 2, 11, 12, 21, 22 ms */
    CHECK_EQ(e[0]->fault, 1);
    CHECK_EQ(e[0]->reason, CANBUS_DROP_FAULT);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 64), 24);
    uint8_t st[16];
    int64_t at[16];
    CHECK_EQ(fault_events(&w, st, at, 16), 6);
    static const int64_t want[] = {1, 3, 11, 13, 21, 23};
    for (int i = 0; i < 6; i++) {
        CHECK_EQ(st[i], i % 2 ? CANBUS_FAULT_CLEARED : CANBUS_FAULT_APPLIED);
        CHECK_EQ(at[i], want[i] * MS);
    }
    /* the applied event comes right before the frame it drops */
    for (size_t i = w.ev_head; i + 1 < w.n_ev; i++)
        if (w.ev[i].kind == CANBUS_EV_FAULT && w.ev[i].reason == CANBUS_FAULT_APPLIED)
            CHECK_EQ(w.ev[i + 1].kind, CANBUS_EV_DROP);
    canbus_wire_fini(&w);
}

static void test_duplicate(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 3; c++)
        canbus_wire_attach(&w, c, true);
    canbus_fault_t f;
    char name[CANBUS_NAME_LEN + 1];
    CHECK_EQ(parse("can_duplicate:fid=x,at=0,client=1,id=0x100,count=1", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 0, 0x100, 1);
    submit(&w, 0, 0x080, 2); /* wins the first arbitration */
    submit(&w, 200000, 0x100, 1); /* past the count: once */
    CHECK_EQ(canbus_wire_run(&w, 10 * MS), 0);
    const canbus_wire_ev_t *e[16];
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 16), 4);
    /* 0x080 wins at 0; then the original 0x100 and its copy back to back; then the third */
    CHECK_EQ(e[0]->id, 0x080);
    CHECK_EQ(e[1]->id, 0x100);
    CHECK_EQ(e[1]->start_ns, 135000);
    CHECK_EQ(e[1]->reason, 0);
    CHECK_EQ(e[2]->id, 0x100);
    CHECK_EQ(e[2]->reason, CANBUS_TX_DUPLICATE);
    CHECK_EQ(e[2]->start_ns, e[1]->end_ns);
    CHECK_EQ(e[2]->fault, 1);
    CHECK(memcmp(e[2]->data, e[1]->data, 8) == 0);
    CHECK_EQ(e[3]->reason, 0);
    CHECK_EQ(w.duplicated, 1);
    CHECK_EQ(w.frames, 4);
    canbus_wire_fini(&w);
}

static void test_transceiver_cut(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 3; c++)
        canbus_wire_attach(&w, c, true);
    canbus_fault_t f;
    char name[CANBUS_NAME_LEN + 1];
    CHECK_EQ(parse("transceiver_cut:fid=c,at=1ms,until=3ms,client=2", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 0, 0x10, 2);       /* before: sent */
    submit(&w, 1 * MS, 0x11, 2);  /* cut: never on the wire */
    submit(&w, 2 * MS, 0x20, 0);  /* on the wire, not received by 2 */
    submit(&w, 3 * MS, 0x12, 2);  /* after: sent */
    submit(&w, 3 * MS, 0x21, 0);  /* after: received by 2 */
    CHECK_EQ(canbus_wire_run(&w, 10 * MS), 0);
    const canbus_wire_ev_t *e[16];
    CHECK_EQ(events(&w, CANBUS_EV_DROP, e, 16), 1);
    CHECK_EQ(e[0]->id, 0x11);
    CHECK_EQ(e[0]->fault, 1);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 16), 4);
    CHECK_EQ(events(&w, CANBUS_EV_RX_DROP, e, 16), 1);
    CHECK_EQ(e[0]->id, 0x20);
    CHECK_EQ(e[0]->to, 2);
    CHECK_EQ(e[0]->client, 0);
    CHECK_EQ(e[0]->start_ns, 2 * MS);
    uint8_t st[8];
    int64_t at[8];
    CHECK_EQ(fault_events(&w, st, at, 8), 2);
    CHECK_EQ(at[0], 1 * MS);
    CHECK_EQ(st[1], CANBUS_FAULT_CLEARED);
    CHECK_EQ(at[1], 3 * MS);
    canbus_wire_fini(&w);

    /* A cut receiver does not see error frames either; rx_drop is about frames only. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 3; c++)
        canbus_wire_attach(&w, c, true);
    CHECK_EQ(parse("transceiver_cut:fid=c,at=0,client=2", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    CHECK_EQ(parse("rx_drop:fid=r,at=0,client=1", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    CHECK_EQ(parse("can_corrupt:fid=e,at=0,id=0x40,count=1", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 0, 0x40, 0);
    CHECK_EQ(canbus_wire_run(&w, 1 * MS), 0);
    CHECK_EQ(events(&w, CANBUS_EV_ERROR, e, 16), 1);
    size_t k = (size_t)(e[0] - w.ev);
    size_t after_error = 0, to_2 = 0;
    for (size_t i = k + 1; i < w.n_ev && w.ev[i].kind != CANBUS_EV_TX; i++)
        if (w.ev[i].kind == CANBUS_EV_RX_DROP) {
            after_error++;
            to_2 += w.ev[i].to == 2;
        }
    CHECK_EQ(after_error, 1);
    CHECK_EQ(to_2, 1);
    CHECK_EQ(events(&w, CANBUS_EV_RX_DROP, e, 16), 3); /* the retransmission: to 2 and to 1 */
    canbus_wire_fini(&w);
}

static void test_rx_drop(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    for (uint8_t c = 0; c < 3; c++)
        canbus_wire_attach(&w, c, true);
    canbus_fault_t f;
    char name[CANBUS_NAME_LEN + 1];
    CHECK_EQ(parse("rx_drop:fid=r,at=0,client=1,id=0x30,count=2", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    for (int i = 0; i < 3; i++)
        submit(&w, i * MS, 0x30, 0);
    submit(&w, 5 * MS, 0x31, 0);
    CHECK_EQ(canbus_wire_run(&w, 10 * MS), 0);
    const canbus_wire_ev_t *e[16];
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 16), 4);
    CHECK_EQ(events(&w, CANBUS_EV_RX_DROP, e, 16), 2); /* count=2 */
    CHECK_EQ(e[0]->to, 1);
    CHECK_EQ(e[1]->start_ns, 1 * MS);
    CHECK_EQ(w.rx_dropped, 2);
    /* each RX_DROP follows its frame (with, for the first, the fault's applied event) */
    size_t k = (size_t)(e[0] - w.ev);
    CHECK_EQ(w.ev[k - 1].kind, CANBUS_EV_FAULT);
    CHECK_EQ(w.ev[k - 2].kind, CANBUS_EV_TX);
    canbus_wire_fini(&w);
}

static void test_bus_off_spell_and_babble(void)
{
    canbus_wire_t w;
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    canbus_wire_attach(&w, 0, true);
    canbus_wire_attach(&w, 1, true);
    canbus_fault_t f;
    char name[CANBUS_NAME_LEN + 1];
    CHECK_EQ(parse("can_bus_off:fid=o,at=1ms,until=4ms,client=1", &f, name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    submit(&w, 2 * MS, 0x10, 1); /* bus-off: dropped */
    submit(&w, 5 * MS, 0x11, 1); /* back on: sent */
    CHECK_EQ(canbus_wire_run(&w, 10 * MS), 0);
    const canbus_wire_ev_t *e[16];
    CHECK_EQ(events(&w, CANBUS_EV_BUS_OFF, e, 16), 1);
    CHECK_EQ(e[0]->end_ns, 1 * MS);
    CHECK_EQ(events(&w, CANBUS_EV_BUS_ON, e, 16), 1);
    CHECK_EQ(e[0]->end_ns, 4 * MS);
    CHECK_EQ(events(&w, CANBUS_EV_DROP, e, 16), 1);
    CHECK_EQ(events(&w, CANBUS_EV_TX, e, 16), 1);
    CHECK_EQ(e[0]->id, 0x11);
    uint8_t st[8];
    int64_t at[8];
    CHECK_EQ(fault_events(&w, st, at, 8), 2);
    CHECK_EQ(st[0], CANBUS_FAULT_APPLIED);
    CHECK_EQ(at[1], 4 * MS);
    canbus_wire_fini(&w);

    /* An intermittent babbler: the bus floods 0x000 for 1 ms every 5 ms, three times. */
    CHECK_EQ(canbus_wire_init(&w, 1000000, 0), 0);
    CHECK_EQ(parse("babbling_idiot:fid=b,at=1ms,period=5ms,on=1ms,until=15ms,id=0,len=8", &f,
                   name), 0);
    CHECK_EQ(canbus_wire_add_fault(&w, &f), 0);
    CHECK_EQ(canbus_wire_run(&w, 20 * MS), 0);
    const canbus_wire_ev_t *tx[32];
    CHECK_EQ(events(&w, CANBUS_EV_TX, tx, 32), 24);
    CHECK_EQ(w.babble_count, 3 * 8); /* 8 frames start in each 1 ms spell */
    CHECK_EQ(fault_events(&w, st, at, 8), 6);
    CHECK_EQ(at[2], 6 * MS);
    CHECK_EQ(at[5], 12 * MS);
    canbus_wire_fini(&w);
}

int main(void)
{
    test_parse_common_grammar();
    test_records_of_new_kinds();
    test_spells();
    test_intermittent_drop_events();
    test_duplicate();
    test_transceiver_cut();
    test_rx_drop();
    test_bus_off_spell_and_babble();
    if (unit_failures)
        fprintf(stderr, "test_canbus_fault: %d check(s) failed\n", unit_failures);
    else
        printf("test_canbus_fault: ok\n");
    return unit_failures ? 1 : 0;
}
