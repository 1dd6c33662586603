/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of io's redundancy: membership from heartbeats (lost after the configured misses,
 * latched), the self-monitor (own command voted out after `persist` miscompares; a peer's too),
 * the input agreement (newest sample, values voted over the members that hold it, never
 * older than what the ports hold), and when mission data and health go to DDS. */
#include <string.h>

#include "io_core.h"
#include "rpas/unit_check.h"

static io_settings_t settings(unsigned channel, uint32_t mask, unsigned misses, unsigned persist)
{
    io_settings_t s;
    memset(&s, 0, sizeof s);
    s.channel = channel;
    s.node_mask = mask;
    s.n_nodes = mask & 4 ? 3 : mask & 2 ? 2 : 1;
    s.membership_misses = misses;
    s.vote_persist = persist;
    for (int i = 0; i < IO_AXES; i++)
        s.vote_threshold[i] = 0.1;
    return s;
}

static void test_membership(void)
{
    io_settings_t s = settings(0, 7, 2, 3);
    io_red_t r;
    CHECK(io_red_init(&r, &s) == 0);
    CHECK(r.members == 7);
    r.peers.hb_seen = 6;
    CHECK(io_membership_update(&r) == 0);
    r.peers.hb_seen = 2; /* node3 misses once: still a member */
    CHECK(io_membership_update(&r) == 0 && r.members == 7);
    r.peers.hb_seen = 6; /* back in time: the count starts again */
    CHECK(io_membership_update(&r) == 0);
    r.peers.hb_seen = 2;
    io_membership_update(&r);
    r.peers.hb_seen = 2;
    CHECK(io_membership_update(&r) == 4 && r.members == 3); /* two misses: lost */
    r.peers.hb_seen = 6;
    CHECK(io_membership_update(&r) == 0 && r.members == 3); /* latched */
    /* its own heartbeat is never needed */
    r.peers.hb_seen = 0;
    for (int i = 0; i < 5; i++)
        io_membership_update(&r);
    CHECK(r.members == 1);
    char text[64];
    io_node_list(5, 3, text, sizeof text);
    CHECK(!strcmp(text, "node1,node3"));
}

static void commands(io_red_t *r, double own, double b, double c)
{
    r->own_cmd.have = true;
    r->own_cmd.v[0] = own;
    r->peers.cmd[1].have = r->peers.cmd[2].have = true;
    r->peers.cmd[1].v[0] = b;
    r->peers.cmd[2].v[0] = c;
}

static void test_self_monitor(void)
{
    io_settings_t s = settings(0, 7, 2, 3);
    io_red_t r;
    io_red_init(&r, &s);
    io_monitor_t m;
    for (int f = 0; f < 2; f++) {
        commands(&r, 0.5, 0.1, 0.1); /* this node's own command is wrong */
        io_self_monitor(&r, &m);
        CHECK(m.newly_failed == 0);
    }
    commands(&r, 0.5, 0.1, 0.1);
    io_self_monitor(&r, &m);
    CHECK(m.newly_failed == 1 && m.own_out && r.own_voted_out);
    CHECK(!strcmp(m.reason[0], "miscompare"));
    CHECK(!r.own_cmd.have && !r.peers.cmd[1].have); /* cleared for the next frame */
    struct xch_health h;
    io_health(&r, 2, &h);
    CHECK(h.failed == 1 && (h.flags & XCH_HEALTH_DISAGREE) && h.membership == 7 && h.fcs_mode == 2);

    io_red_init(&r, &s);
    for (int f = 0; f < 3; f++) {
        commands(&r, 0.1, 0.1, -0.4); /* node3 is wrong */
        io_self_monitor(&r, &m);
    }
    CHECK(m.newly_failed == 4 && !m.own_out && r.peers_voted_out == 4);
    /* without a command of its own, nothing is voted (start-up) */
    io_red_init(&r, &s);
    for (int f = 0; f < 5; f++) {
        commands(&r, 0.1, 0.9, 0.9);
        r.own_cmd.have = false;
        io_self_monitor(&r, &m);
        CHECK(m.newly_failed == 0);
    }
    /* a single node has nothing to compare with */
    io_settings_t one = settings(0, 1, 2, 1);
    io_red_init(&r, &one);
    commands(&r, 0.9, 0, 0);
    io_self_monitor(&r, &m);
    CHECK(m.newly_failed == 0 && !r.selfmon_on);
}

static struct xch_inputs air_sample(int64_t t, uint32_t seq, double ias)
{
    struct xch_inputs in;
    memset(&in, 0, sizeof in);
    in.valid = XCH_IN_AIR;
    in.air_t_ns = t;
    in.air_seq = seq;
    in.air[0] = ias;
    in.air[1] = 3000;
    return in;
}

/* Node 2 of three, its ports empty, and an agreement with all three present. */
static void agreement_setup(io_red_t *r, io_rx_t *rx, struct xch_agreed *ag)
{
    io_settings_t s = settings(1, 7, 2, 3);
    io_red_init(r, &s);
    io_rx_init(rx);
    memset(ag, 0, sizeof *ag);
    ag->present = 7;
}

static void test_agreement(void)
{
    io_red_t r;
    io_rx_t rx;
    struct xch_agreed ag;
    agreement_setup(&r, &rx, &ag);
    ag.in[0] = air_sample(100, 4, 100.0);
    ag.in[1] = air_sample(100, 4, 101.0);
    ag.in[2] = air_sample(100, 4, 130.0);
    io_apply_agreed(&r, &rx, &ag, 1000);
    CHECK(rx.air_new && rx.air.t_ns == 100 && rx.air.seq == 4);
    CHECK_NEAR(rx.air.ias_kt, 101.0, 0); /* the median of the three copies */
    CHECK(!rx.gps_new && !rx.ahrs_new);  /* nobody holds one */
    io_rx_written(&rx);

    /* a newer sample held by one node wins; the older copies are not voted with it */
    ag.in[2] = air_sample(150, 5, 120.0);
    io_apply_agreed(&r, &rx, &ag, 1000);
    CHECK(rx.air_new && rx.air.t_ns == 150);
    CHECK_NEAR(rx.air.ias_kt, 120.0, 0);
    io_rx_written(&rx);

    /* nothing newer than what the port holds: not written again */
    io_apply_agreed(&r, &rx, &ag, 1000);
    CHECK(!rx.air_new);

    /* a node not present does not count */
    ag.present = 3;
    ag.in[0] = air_sample(200, 6, 90.0);
    ag.in[1] = air_sample(200, 6, 92.0);
    ag.in[2] = air_sample(900, 9, 0.0);
    io_apply_agreed(&r, &rx, &ag, 1000);
    CHECK(rx.air.t_ns == 200);
    CHECK_NEAR(rx.air.ias_kt, 91.0, 1e-12); /* the average of two */
}

/* Samples stamped after the frame's end or older than their port's refresh period are left
 * out, whatever they hold: a forged far-future stamp would otherwise always be the newest. */
static void test_agreement_time_bounds(void)
{
    io_red_t r;
    io_rx_t rx;
    struct xch_agreed ag;
    agreement_setup(&r, &rx, &ag);
    r.frame_ns = 50;
    r.max_age_ns[2] = 200; /* air data */
    ag.in[0] = air_sample(900, 4, 100.0);
    ag.in[1] = air_sample(900, 4, 100.0);
    ag.in[2] = air_sample(1000000, 5, 500.0); /* far in the future */
    io_apply_agreed(&r, &rx, &ag, 1000);
    CHECK(rx.air_new && rx.air.t_ns == 900);
    CHECK_NEAR(rx.air.ias_kt, 100.0, 0);
    CHECK(r.refused_stamps[2] == 1 && r.refused_stamps[0] == 0 && r.refused_new == 4);
    io_rx_written(&rx);

    /* within the frame (its end included) it counts */
    r.refused_new = 0;
    ag.in[2] = air_sample(1050, 6, 104.0);
    io_apply_agreed(&r, &rx, &ag, 1000);
    CHECK(rx.air_new && rx.air.t_ns == 1050 && r.refused_new == 0);
    io_rx_written(&rx);

    /* older than the refresh period: stale, left out even when it is all there is */
    ag.present = 1;
    ag.in[0] = air_sample(1100, 7, 99.0);
    io_apply_agreed(&r, &rx, &ag, 1301);
    CHECK(!rx.air_new && r.refused_stamps[0] == 1);
    io_apply_agreed(&r, &rx, &ag, 1300);
    CHECK(rx.air_new && rx.air.t_ns == 1100);
}

static void test_inputs(void)
{
    io_rx_t rx;
    io_rx_init(&rx);
    struct xch_inputs in;
    io_inputs(&rx, &in);
    CHECK(in.valid == 0);
    rx.gps.t_ns = 5;
    rx.gps.lat_deg = 47;
    rx.ahrs.t_ns = 6;
    rx.ahrs.az_g = -1;
    io_inputs(&rx, &in);
    CHECK(in.valid == (XCH_IN_GPS | XCH_IN_AHRS));
    CHECK(in.gps[0] == 47 && in.ahrs[8] == -1 && in.ahrs_t_ns == 6);
}

static void test_mission_due(void)
{
    io_settings_t s = settings(0, 7, 2, 3);
    io_red_t r;
    io_red_init(&r, &s);
    rpas_pilot_msg_t p = {.mode = 2, .hdg_deg = 90};
    struct xch_mission m;
    CHECK(!io_mission_due(&r, &p, 0, &m)); /* no targets yet */
    p.have_targets = 1;
    CHECK(io_mission_due(&r, &p, 1, &m) && m.hdg_deg == 90);
    CHECK(!io_mission_due(&r, &p, 2, &m));  /* unchanged */
    CHECK(io_mission_due(&r, &p, 21, &m));  /* once a second (20 frames) */
    p.hdg_deg = 91;
    CHECK(io_mission_due(&r, &p, 22, &m) && m.hdg_deg == 91); /* changed */
}

static void test_health_due(void)
{
    io_settings_t s = settings(0, 7, 2, 3);
    io_red_t r;
    io_red_init(&r, &s);
    struct xch_health h;
    io_health(&r, 2, &h);
    CHECK(io_health_due(&r, &h, 5));  /* the first one */
    CHECK(!io_health_due(&r, &h, 6)); /* unchanged */
    CHECK(!io_health_due(&r, &h, 5 + IO_HEALTH_REFRESH_FRAMES - 1));
    CHECK(io_health_due(&r, &h, 5 + IO_HEALTH_REFRESH_FRAMES)); /* once a second */
    r.members = 3;                                              /* node3 lost */
    io_health(&r, 2, &h);
    CHECK(io_health_due(&r, &h, 26) && h.membership == 3); /* changed: at once */
    io_health(&r, 3, &h);
    CHECK(io_health_due(&r, &h, 27)); /* the flight-control mode changed */
    r.health_sent = false;            /* a new agent */
    CHECK(io_health_due(&r, &h, 28));
    CHECK(!io_health_due(&r, &h, 29));
}

int main(void)
{
    RUN(test_membership);
    RUN(test_self_monitor);
    RUN(test_agreement);
    RUN(test_agreement_time_bounds);
    RUN(test_inputs);
    RUN(test_mission_due);
    RUN(test_health_due);
    return UNIT_RESULT();
}
