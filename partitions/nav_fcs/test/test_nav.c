/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the nav_fcs navigation core: source validity (port flag, freshness, frozen
 * counters), GPS position, wind estimate, dead reckoning on a lost or frozen GPS. */
#include <string.h>

#include "nav.h"
#include "nf_math.h"
#include "rpas/unit_check.h"

#define MS 1000000LL
#define LAT0 43.6
#define LON0 1.4

/* A simulated aircraft flying straight at constant TAS and heading in a constant wind, and
 * the sensor messages it produces. */
typedef struct {
    double lat, lon, alt_ft, ias_kt, hdg_deg, wind_n, wind_e;
    uint32_t gps_seq, ahrs_seq, air_seq;
    nav_inputs_t in;
} sim_t;

static void sim_init(sim_t *s, double hdg, double wind_n, double wind_e)
{
    memset(s, 0, sizeof *s);
    s->lat = LAT0;
    s->lon = LON0;
    s->alt_ft = 3000.0;
    s->ias_kt = 100.0;
    s->hdg_deg = hdg;
    s->wind_n = wind_n;
    s->wind_e = wind_e;
}

static void sim_ground_velocity(const sim_t *s, double *vn, double *ve)
{
    double tas = nf_tas_from_ias(s->ias_kt, s->alt_ft);
    *vn = tas * cos(s->hdg_deg * NF_DEG) + s->wind_n;
    *ve = tas * sin(s->hdg_deg * NF_DEG) + s->wind_e;
}

/* Advances the truth by dt and refreshes the messages; GPS every 200 ms unless frozen
 * (a frozen receiver keeps sending its last GPS_CNT and data). */
static void sim_step(sim_t *s, int64_t now, double dt, bool gps_frozen)
{
    double vn, ve;
    sim_ground_velocity(s, &vn, &ve);
    s->lat += vn * NF_KT_MPS * dt / NF_EARTH_R_M / NF_DEG;
    s->lon += ve * NF_KT_MPS * dt / (NF_EARTH_R_M * cos(s->lat * NF_DEG)) / NF_DEG;
    nav_inputs_t *in = &s->in;
    if (now % (200 * MS) == 0) {
        in->gps.t_ns = now;
        if (!gps_frozen) {
            in->gps.seq = ++s->gps_seq;
            in->gps.fix = 3;
            in->gps.sats = 9;
            in->gps.lat_deg = s->lat;
            in->gps.lon_deg = s->lon;
            in->gps.alt_ft = s->alt_ft + 20.0;
            in->gps.gs_kt = hypot(vn, ve);
            in->gps.trk_deg = nf_wrap360(atan2(ve, vn) / NF_DEG);
        }
        in->gps_ok = true;
    }
    in->ahrs.t_ns = now;
    in->ahrs.seq = ++s->ahrs_seq;
    in->ahrs.status = 3;
    in->ahrs.roll_deg = 0.0;
    in->ahrs.pitch_deg = 2.0;
    in->ahrs.hdg_deg = s->hdg_deg;
    in->ahrs.az_g = -1.0;
    in->ahrs.r_dps = 0.001 * (double)(s->ahrs_seq % 1000); /* an AHRS is never constant */
    in->ahrs_ok = true;
    in->air.t_ns = now;
    in->air.seq = ++s->air_seq;
    in->air.status = 1;
    in->air.ias_kt = s->ias_kt;
    in->air.alt_ft = s->alt_ft;
    in->air.vs_fpm = 0.0;
    in->air_ok = true;
}

/* Distance in metres between two positions (flat Earth: short distances). */
static double dist_m(double lat1, double lon1, double lat2, double lon2)
{
    double dn = (lat2 - lat1) * NF_DEG * NF_EARTH_R_M;
    double de = (lon2 - lon1) * NF_DEG * NF_EARTH_R_M * cos(lat1 * NF_DEG);
    return hypot(dn, de);
}

static void fly(nav_t *nav, sim_t *s, int64_t *now, double seconds, bool gps_frozen, rpas_nav_msg_t *out)
{
    for (int i = 0; i < (int)(seconds / 0.05 + 0.5); i++) {
        *now += 50 * MS;
        sim_step(s, *now, 0.05, gps_frozen);
        nav_update(nav, &s->in, *now, out);
    }
}

static void test_all_sources_valid(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 90.0, 0.0, 0.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 2.0, false, &o);
    CHECK(o.flags == (RPAS_NAV_GPS | RPAS_NAV_AHRS | RPAS_NAV_AIR));
    CHECK(o.t_ns == now);
    CHECK_NEAR(o.alt_ft, 3000.0, 1e-9); /* baro, not the GPS's +20 ft */
    CHECK_NEAR(o.ias_kt, 100.0, 1e-9);
    CHECK_NEAR(o.hdg_deg, 90.0, 1e-9);
    CHECK_NEAR(o.pitch_deg, 2.0, 1e-9);
    CHECK(dist_m(o.lat_deg, o.lon_deg, s.lat, s.lon) < 1.0);
    CHECK_NEAR(o.trk_deg, 90.0, 1e-6);
    CHECK_NEAR(o.gs_kt, nf_tas_from_ias(100.0, 3000.0), 1e-6);
}

static void test_wind_estimate(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 90.0, -8.0, 6.0); /* 10 kt from 323 deg */
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 120.0, false, &o);
    CHECK_NEAR(o.wind_n_kt, -8.0, 0.05);
    CHECK_NEAR(o.wind_e_kt, 6.0, 0.05);
}

/* A frozen receiver repeats GPS_CNT: dropped after gps_frozen_s, then dead reckoning from
 * TAS, heading and the wind estimate keeps the position. */
static void test_frozen_gps_dead_reckoning(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 45.0, 5.0, -7.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 120.0, false, &o);
    CHECK(o.flags & RPAS_NAV_GPS);

    fly(&nav, &s, &now, 0.5, true, &o); /* not yet: the counter stopped 0.5 s ago at most */
    CHECK(o.flags & RPAS_NAV_GPS);
    fly(&nav, &s, &now, 0.5, true, &o);
    CHECK(!(o.flags & RPAS_NAV_GPS));
    CHECK(o.flags & RPAS_NAV_DR);
    CHECK(o.flags & RPAS_NAV_AHRS);

    fly(&nav, &s, &now, 120.0, true, &o);
    CHECK(!(o.flags & RPAS_NAV_GPS));
    CHECK(o.flags & RPAS_NAV_DR);
    /* two minutes at ~105 kt TAS: a few km flown; the error stays a few metres */
    CHECK(dist_m(o.lat_deg, o.lon_deg, s.lat, s.lon) < 20.0);
    /* the frozen fix would be 3.5 km behind */
    CHECK(dist_m(s.in.gps.lat_deg, s.in.gps.lon_deg, s.lat, s.lon) > 3000.0);
    double vn, ve;
    sim_ground_velocity(&s, &vn, &ve);
    CHECK_NEAR(o.gs_kt, hypot(vn, ve), 0.2);
    CHECK_NEAR(nf_wrap180(o.trk_deg - atan2(ve, vn) / NF_DEG), 0.0, 0.2);

    /* the receiver comes back: GPS again at its next counter */
    fly(&nav, &s, &now, 0.4, false, &o);
    CHECK(o.flags & RPAS_NAV_GPS);
    CHECK(!(o.flags & RPAS_NAV_DR));
    CHECK(dist_m(o.lat_deg, o.lon_deg, s.lat, s.lon) < 1.0);
}

/* A lost GPS (port invalid) goes to dead reckoning at once; the wind estimate is frozen. */
static void test_lost_gps(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 270.0, 0.0, 10.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 120.0, false, &o);
    double wn = o.wind_n_kt, we = o.wind_e_kt;
    int64_t t_loss = now;
    for (int i = 0; i < 1200; i++) {
        now += 50 * MS;
        sim_step(&s, now, 0.05, false);
        s.in.gps_ok = false;
        s.in.gps.seq++; /* whatever the message says, an invalid port is not used */
        s.in.gps.lat_deg = 0.0;
        nav_update(&nav, &s.in, now, &o);
    }
    CHECK(now - t_loss == 60000 * MS);
    CHECK(o.flags == (RPAS_NAV_DR | RPAS_NAV_AHRS | RPAS_NAV_AIR));
    CHECK_NEAR(o.wind_n_kt, wn, 1e-12);
    CHECK_NEAR(o.wind_e_kt, we, 1e-12);
    CHECK(dist_m(o.lat_deg, o.lon_deg, s.lat, s.lon) < 10.0);
}

static void test_stale_or_bad_gps_rejected(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 0.0, 0.0, 0.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 5.0, false, &o);
    CHECK(o.flags & RPAS_NAV_GPS);

    /* no fix */
    s.in.gps.fix = 0;
    s.in.gps.seq++;
    now += 50 * MS;
    nav_update(&nav, &s.in, now, &o);
    CHECK(!(o.flags & RPAS_NAV_GPS));
    CHECK(o.flags & RPAS_NAV_DR);

    /* a NaN latitude */
    fly(&nav, &s, &now, 1.0, false, &o);
    CHECK(o.flags & RPAS_NAV_GPS);
    s.in.gps.lat_deg = NAN;
    s.in.gps.seq++;
    now += 50 * MS;
    nav_update(&nav, &s.in, now, &o);
    CHECK(!(o.flags & RPAS_NAV_GPS));
    CHECK(isfinite(o.lat_deg));

    /* a message whose own time stamp is too old, though the port says valid */
    fly(&nav, &s, &now, 1.0, false, &o);
    s.in.gps.t_ns = now - 1500 * MS;
    s.in.gps.seq++;
    now += 50 * MS;
    nav_update(&nav, &s.in, now, &o);
    CHECK(!(o.flags & RPAS_NAV_GPS));
}

static void test_no_dead_reckoning_without_a_first_fix(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 0.0, 0.0, 0.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    for (int i = 0; i < 40; i++) {
        now += 50 * MS;
        sim_step(&s, now, 0.05, false);
        s.in.gps_ok = false;
        nav_update(&nav, &s.in, now, &o);
    }
    CHECK(o.flags == (RPAS_NAV_AHRS | RPAS_NAV_AIR));
}

static void test_ahrs_and_air_monitoring(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 0.0, 0.0, 0.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 1.0, false, &o);
    CHECK(o.flags & RPAS_NAV_AHRS);

    /* frozen AHRS counter: dropped after ahrs_frozen_s (0.2 s) */
    uint32_t frozen = s.in.ahrs.seq;
    for (int i = 0; i < 5; i++) {
        now += 50 * MS;
        sim_step(&s, now, 0.05, false);
        s.in.ahrs.seq = frozen;
        nav_update(&nav, &s.in, now, &o);
        if (i < 3)
            CHECK(o.flags & RPAS_NAV_AHRS);
    }
    CHECK(!(o.flags & RPAS_NAV_AHRS));
    CHECK(!(o.flags & RPAS_NAV_DR)); /* GPS still good: no dead reckoning */

    /* not aligned */
    fly(&nav, &s, &now, 0.5, false, &o);
    CHECK(o.flags & RPAS_NAV_AHRS);
    s.in.ahrs.status = 1;
    s.in.ahrs.seq++;
    now += 50 * MS;
    nav_update(&nav, &s.in, now, &o);
    CHECK(!(o.flags & RPAS_NAV_AHRS));

    /* air data: invalid status, then a port INVALID; baro altitude is held, GPS altitude used */
    fly(&nav, &s, &now, 0.5, false, &o);
    CHECK(o.flags & RPAS_NAV_AIR);
    s.in.air.status = 0;
    s.in.air.seq++;
    now += 50 * MS;
    nav_update(&nav, &s.in, now, &o);
    CHECK(!(o.flags & RPAS_NAV_AIR));
    CHECK_NEAR(o.alt_ft, 3020.0, 1e-9); /* the GPS altitude of sim_step */
    fly(&nav, &s, &now, 0.5, false, &o);
    s.in.air_ok = false;
    now += 50 * MS;
    nav_update(&nav, &s.in, now, &o);
    CHECK(!(o.flags & RPAS_NAV_AIR));
}

/* An AHRS stuck behind a live counter: every value repeats, the counter and the status run on.
 * Dropped after ahrs_stuck_s (0.5 s), back as soon as the values move again. */
static void test_stuck_ahrs(void)
{
    nav_t nav;
    nav_init(&nav, NULL);
    sim_t s;
    sim_init(&s, 90.0, 0.0, 0.0);
    rpas_nav_msg_t o;
    int64_t now = 0;
    fly(&nav, &s, &now, 2.0, false, &o);
    CHECK(o.flags & RPAS_NAV_AHRS);
    rpas_ahrs_msg_t stuck = s.in.ahrs;
    int valid_for = 0;
    for (int i = 0; i < 20; i++) {
        now += 50 * MS;
        sim_step(&s, now, 0.05, false);
        uint32_t seq = s.in.ahrs.seq;
        s.in.ahrs = stuck;
        s.in.ahrs.seq = seq; /* the counter keeps running */
        s.in.ahrs.t_ns = now;
        nav_update(&nav, &s.in, now, &o);
        if (o.flags & RPAS_NAV_AHRS)
            valid_for++;
    }
    CHECK(valid_for == 9); /* 0.45 s after the last change: still good; at 0.5 s: stuck */
    CHECK(!(o.flags & RPAS_NAV_AHRS));
    CHECK(o.flags & RPAS_NAV_GPS);
    fly(&nav, &s, &now, 0.05, false, &o);
    CHECK(o.flags & RPAS_NAV_AHRS);
}

int main(void)
{
    RUN(test_all_sources_valid);
    RUN(test_wind_estimate);
    RUN(test_frozen_gps_dead_reckoning);
    RUN(test_lost_gps);
    RUN(test_stale_or_bad_gps_rejected);
    RUN(test_no_dead_reckoning_without_a_first_fix);
    RUN(test_ahrs_and_air_monitoring);
    RUN(test_stuck_ahrs);
    return UNIT_RESULT();
}
