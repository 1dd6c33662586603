/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the nav_fcs flight-control core: modes and fallbacks, limits, anti-windup,
 * bumpless entry, envelope protection, angle wrapping, determinism; the degraded modes (attitude
 * or air data unusable). */
#include <string.h>

#include "fcs.h"
#include "nf_math.h"
#include "rpas/unit_check.h"

#define MS 1000000LL

typedef struct {
    fcs_t fcs;
    fcs_inputs_t in;
    rpas_nav_msg_t nav;
    rpas_act_cmd_msg_t cmd;
    rpas_fcs_status_msg_t st;
    int64_t now;
    bool stick; /* the station sends its stick in every mode (it does: PILOT_STICK at 20 Hz) */
} rig_t;

/* Level flight at 3000 ft, 100 kt, heading 090; pilot link up asking for mode. */
static void rig_init(rig_t *r, uint32_t mode)
{
    memset(r, 0, sizeof *r);
    fcs_init(&r->fcs, NULL);
    r->nav.flags = RPAS_NAV_GPS | RPAS_NAV_AHRS | RPAS_NAV_AIR;
    r->nav.alt_ft = 3000.0;
    r->nav.ias_kt = 100.0;
    r->nav.hdg_deg = 90.0;
    r->nav.trk_deg = 90.0;
    r->nav.gs_kt = 104.0;
    r->nav.pitch_deg = 1.0;
    r->in.ahrs.status = 3;
    r->in.pilot.mode = mode;
    r->in.pilot_ok = true;
    r->in.act_ok = true;
    r->in.act.thr = 0.7;
}

static void set_pilot_targets(rig_t *r, double hdg, double alt, double ias)
{
    r->in.pilot.have_targets = 1;
    r->in.pilot.hdg_deg = hdg;
    r->in.pilot.alt_ft = alt;
    r->in.pilot.ias_kt = ias;
}

/* One 50 ms cycle; the pilot message is refreshed while the link is up, the actuators follow
 * the command exactly. */
static void step(rig_t *r)
{
    r->now += 50 * MS;
    if (r->in.pilot_ok) {
        r->in.pilot.t_ns = r->now;
        if (r->in.pilot.mode == RPAS_MODE_DIRECT || r->stick)
            r->in.pilot.t_stick_ns = r->now;
    }
    r->nav.t_ns = r->now;
    r->in.act.t_ns = r->now;
    fcs_step(&r->fcs, &r->in, &r->nav, r->now, &r->cmd, &r->st);
    r->in.act.elev = r->cmd.elev;
    r->in.act.ail = r->cmd.ail;
    r->in.act.rud = r->cmd.rud;
    r->in.act.thr = r->cmd.thr;
}

static void steps(rig_t *r, int n)
{
    for (int i = 0; i < n; i++)
        step(r);
}

static bool cmd_in_range(const rpas_act_cmd_msg_t *c)
{
    return isfinite(c->elev) && isfinite(c->ail) && isfinite(c->rud) && isfinite(c->thr) &&
           fabs(c->elev) <= 1.0 && fabs(c->ail) <= 1.0 && fabs(c->rud) <= 1.0 && c->thr >= 0.0 &&
           c->thr <= 1.0;
}

static void test_direct_maps_stick(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_DIRECT);
    r.in.pilot.stk_pitch = 0.5; /* pull */
    r.in.pilot.stk_roll = 0.3;
    r.in.pilot.stk_yaw = -0.2;
    r.in.pilot.stk_thr = 0.9;
    steps(&r, 30); /* past the 1 s blend */
    CHECK(r.st.mode == RPAS_MODE_DIRECT);
    CHECK(r.st.req_mode == RPAS_MODE_DIRECT);
    CHECK(r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.cmd.elev, -0.5, 1e-12); /* pull = nose up = elevator negative */
    CHECK_NEAR(r.cmd.ail, 0.3, 1e-12);
    CHECK_NEAR(r.cmd.rud, -0.2, 1e-12);
    CHECK_NEAR(r.cmd.thr, 0.9, 1e-12);
    CHECK(r.st.env_flags == 0);
    /* a stick beyond full scale is limited */
    r.in.pilot.stk_pitch = -3.0;
    r.in.pilot.stk_thr = 7.0;
    step(&r);
    CHECK_NEAR(r.cmd.elev, 1.0, 1e-12);
    CHECK_NEAR(r.cmd.thr, 1.0, 1e-12);
}

static void test_direct_envelope_protection(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_DIRECT);
    r.in.pilot.stk_roll = 1.0;
    r.in.pilot.stk_pitch = 1.0;
    r.in.pilot.stk_thr = 0.7;
    steps(&r, 30);
    CHECK_NEAR(r.cmd.ail, 1.0, 1e-12);
    /* beyond the bank limit (45 deg) the aileron is pulled back against the pilot */
    r.nav.roll_deg = 50.0;
    step(&r);
    CHECK(r.cmd.ail < 0.0);
    CHECK(r.st.env_flags & FCS_ENV_BANK);
    r.nav.roll_deg = -50.0;
    r.in.pilot.stk_roll = -1.0;
    step(&r);
    CHECK(r.cmd.ail > 0.0);
    /* beyond +20 deg pitch a full pull gives nose-down elevator */
    r.nav.roll_deg = 0.0;
    r.nav.pitch_deg = 23.0;
    step(&r);
    CHECK(r.cmd.elev > 0.0);
    CHECK(r.st.env_flags & FCS_ENV_PITCH);
    /* below -15 deg a full push gives nose-up elevator */
    r.nav.pitch_deg = -18.0;
    r.in.pilot.stk_pitch = -1.0;
    step(&r);
    CHECK(r.cmd.elev < 0.0);
    /* under-speed: full throttle, no nose-up elevator */
    r.nav.pitch_deg = 5.0;
    r.in.pilot.stk_pitch = 1.0;
    r.in.pilot.stk_thr = 0.2;
    r.nav.ias_kt = 50.0;
    step(&r);
    CHECK(r.st.env_flags & FCS_ENV_UNDERSPEED);
    CHECK_NEAR(r.cmd.thr, 1.0, 1e-12);
    CHECK(r.cmd.elev > 0.0);
    /* over-speed: throttle cut, no nose-down elevator */
    r.nav.ias_kt = 150.0;
    r.in.pilot.stk_pitch = -1.0;
    r.in.pilot.stk_thr = 1.0;
    step(&r);
    CHECK(r.st.env_flags & FCS_ENV_OVERSPEED);
    CHECK(r.cmd.thr <= r.fcs.prm.thr_min + 1e-12);
    CHECK(r.cmd.elev < 0.0);
}

/* C2 link lost in DIRECT: AUTOPILOT holding the state of the moment of the loss. */
static void test_c2_loss_in_direct(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_DIRECT);
    r.in.pilot.stk_thr = 0.7;
    r.nav.hdg_deg = 123.0;
    r.nav.alt_ft = 3456.0;
    r.nav.ias_kt = 97.0;
    steps(&r, 10);
    CHECK(r.st.mode == RPAS_MODE_DIRECT);
    r.in.pilot_ok = false;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.req_mode == RPAS_MODE_DIRECT);
    CHECK(r.st.fallback == RPAS_FB_C2_LOST);
    CHECK_NEAR(r.st.tgt_hdg_deg, 123.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 3456.0, 1e-9);
    CHECK_NEAR(r.st.tgt_ias_kt, 97.0, 1e-9);
    CHECK(r.st.lat_mode == RPAS_LAT_HDG && r.st.vert_mode == RPAS_VERT_ALT);
    /* the targets were captured once: the aircraft moving does not move them */
    r.nav.hdg_deg = 140.0;
    r.nav.alt_ft = 3300.0;
    steps(&r, 20);
    CHECK_NEAR(r.st.tgt_hdg_deg, 123.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 3456.0, 1e-9);
    /* stick frames stop while the link is up: the same fallback */
    rig_init(&r, RPAS_MODE_DIRECT);
    steps(&r, 5);
    r.in.pilot.t_stick_ns = r.now - 2000 * MS; /* by hand: step() would refresh it */
    r.now += 50 * MS;
    r.in.pilot.t_ns = r.now;
    fcs_step(&r.fcs, &r.in, &r.nav, r.now, &r.cmd, &r.st);
    CHECK(r.st.fallback == RPAS_FB_C2_LOST);
    /* the link comes back: DIRECT again */
    rig_init(&r, RPAS_MODE_DIRECT);
    steps(&r, 5);
    r.in.pilot_ok = false;
    steps(&r, 5);
    r.in.pilot_ok = true;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_DIRECT);
    CHECK(r.st.fallback == RPAS_FB_NONE);
}

/* C2 link lost in AUTOPILOT: the pilot's targets stay. */
static void test_c2_loss_in_autopilot(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 200.0, 4000.0, 110.0);
    steps(&r, 10);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.st.tgt_hdg_deg, 200.0, 1e-9);
    r.in.pilot_ok = false;
    r.in.pilot.hdg_deg = 10.0; /* an invalid port's content is ignored */
    steps(&r, 40);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK_NEAR(r.st.tgt_hdg_deg, 200.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 4000.0, 1e-9);
    CHECK_NEAR(r.st.tgt_ias_kt, 110.0, 1e-9);
}

static void test_autopilot_without_targets_holds(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    r.nav.hdg_deg = 271.0;
    r.nav.alt_ft = 2500.0;
    steps(&r, 5);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.fallback == RPAS_FB_NO_TARGETS);
    CHECK_NEAR(r.st.tgt_hdg_deg, 271.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 2500.0, 1e-9);
    set_pilot_targets(&r, 10.0, 3000.0, 100.0);
    step(&r);
    CHECK(r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.st.tgt_hdg_deg, 10.0, 1e-9);
    /* no pilot message ever: C2_LOST hold */
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    r.in.pilot_ok = false;
    steps(&r, 3);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.req_mode == RPAS_MODE_INIT);
    CHECK(r.st.fallback == RPAS_FB_C2_LOST);
}

static void set_mission(rig_t *r, uint32_t mode, double hdg, double alt, double ias)
{
    r->in.mission_ok = true;
    r->in.mission.t_ns = r->now;
    r->in.mission.mode = mode;
    r->in.mission.lat_mode = RPAS_LAT_TRK;
    r->in.mission.vert_mode = RPAS_VERT_ALT;
    r->in.mission.hdg_deg = hdg;
    r->in.mission.alt_ft = alt;
    r->in.mission.ias_kt = ias;
}

static void mission_steps(rig_t *r, int n, bool fresh)
{
    for (int i = 0; i < n; i++) {
        if (fresh)
            r->in.mission.t_ns = r->now + 50 * MS;
        step(r);
    }
}

static void test_mission_and_stale_fallback(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_MISSION);
    set_mission(&r, RPAS_MODE_MISSION, 45.0, 3500.0, 95.0);
    mission_steps(&r, 10, true);
    CHECK(r.st.mode == RPAS_MODE_MISSION);
    CHECK(r.st.fallback == RPAS_FB_NONE);
    CHECK(r.st.lat_mode == RPAS_LAT_TRK);
    CHECK_NEAR(r.st.tgt_hdg_deg, 45.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 3500.0, 1e-9);
    CHECK_NEAR(r.st.tgt_ias_kt, 95.0, 1e-9);
    r.in.mission.mode = RPAS_MODE_CONTINGENCY;
    mission_steps(&r, 1, true);
    CHECK(r.st.mode == RPAS_MODE_CONTINGENCY);

    /* the mission manager stops writing: its message ages past 1 s (port still valid) */
    r.nav.hdg_deg = 77.0;
    r.nav.alt_ft = 3111.0;
    r.nav.ias_kt = 99.0;
    mission_steps(&r, 20, false);
    CHECK(r.st.mode == RPAS_MODE_CONTINGENCY);
    mission_steps(&r, 2, false);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.req_mode == RPAS_MODE_MISSION);
    CHECK(r.st.fallback == RPAS_FB_MISSION_STALE);
    CHECK(r.st.lat_mode == RPAS_LAT_HDG && r.st.vert_mode == RPAS_VERT_ALT);
    CHECK_NEAR(r.st.tgt_hdg_deg, 77.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 3111.0, 1e-9);
    CHECK_NEAR(r.st.tgt_ias_kt, 99.0, 1e-9);

    /* fresh again: re-engaged only after 1 s of good messages */
    r.in.mission.mode = RPAS_MODE_MISSION;
    mission_steps(&r, 10, true);
    CHECK(r.st.fallback == RPAS_FB_MISSION_STALE);
    mission_steps(&r, 15, true);
    CHECK(r.st.mode == RPAS_MODE_MISSION);
    CHECK(r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.st.tgt_hdg_deg, 45.0, 1e-9);

    /* port INVALID at once */
    r.in.mission_ok = false;
    step(&r);
    CHECK(r.st.fallback == RPAS_FB_MISSION_STALE);
    /* a mission message with a bad mode or NaN is not used */
    rig_init(&r, RPAS_MODE_MISSION);
    set_mission(&r, RPAS_MODE_DIRECT, 45.0, 3500.0, 95.0);
    mission_steps(&r, 3, true);
    CHECK(r.st.fallback == RPAS_FB_MISSION_STALE);
    set_mission(&r, RPAS_MODE_MISSION, NAN, 3500.0, 95.0);
    mission_steps(&r, 3, true);
    CHECK(r.st.fallback == RPAS_FB_MISSION_STALE);
    CHECK(cmd_in_range(&r.cmd));
}

/* The landing phases and flight termination the mission manager flags. */
static void test_landing_flags_and_termination(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_MISSION);
    set_mission(&r, RPAS_MODE_MISSION, 90.0, 3000.0, 58.0);
    r.in.mission.flags = RPAS_MSN_APPROACH;
    r.nav.ias_kt = 58.0;
    mission_steps(&r, 30, true);
    CHECK(r.st.mode == RPAS_MODE_MISSION && r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.st.tgt_ias_kt, 58.0, 1e-9); /* under the usual 65 kt floor */
    CHECK(!(r.st.env_flags & FCS_ENV_UNDERSPEED)); /* 58 kt is no under-speed on a final */
    r.in.mission.flags = RPAS_MSN_FLARE;
    mission_steps(&r, 2, true);
    CHECK_NEAR(r.cmd.thr, 0.0, 0.0); /* idle */
    CHECK_NEAR(r.cmd.brake, 0.0, 0.0);
    /* on the runway: idle, wings level, steering to the course, brakes once slow */
    r.in.mission.flags = RPAS_MSN_ROLLOUT;
    r.in.mission.hdg_deg = 95.0;
    r.nav.gs_kt = 60.0;
    mission_steps(&r, 1, true);
    CHECK_NEAR(r.cmd.thr, 0.0, 0.0);
    CHECK_NEAR(r.cmd.ail, 0.0, 0.0);
    CHECK(r.cmd.rud > 0.0); /* right, towards 095 */
    CHECK_NEAR(r.cmd.brake, 0.0, 0.0); /* too fast for the brakes yet */
    r.nav.gs_kt = 40.0;
    mission_steps(&r, 1, true);
    CHECK(r.cmd.brake > 0.4f);
    /* flight termination: the engine cut, also without attitude */
    rig_init(&r, RPAS_MODE_MISSION);
    set_mission(&r, RPAS_MODE_CONTINGENCY, 90.0, 2000.0, 65.0);
    r.in.mission.flags = RPAS_MSN_TERMINATE;
    mission_steps(&r, 30, true);
    CHECK_NEAR(r.cmd.thr, 0.0, 0.0);
    r.nav.flags = RPAS_NAV_GPS | RPAS_NAV_AIR;
    mission_steps(&r, 3, true);
    CHECK(r.st.fallback == RPAS_FB_NAV_INVALID);
    CHECK_NEAR(r.cmd.thr, 0.0, 0.0);
}

static void test_nav_invalid(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 180.0, 3000.0, 100.0);
    r.nav.flags = RPAS_NAV_GPS | RPAS_NAV_AIR; /* no attitude from the start */
    steps(&r, 3);
    CHECK(r.st.mode == RPAS_MODE_INIT);
    CHECK(r.st.fallback == RPAS_FB_NAV_INVALID);
    CHECK_NEAR(r.cmd.ail, 0.0, 0.0);
    r.nav.flags |= RPAS_NAV_AHRS;
    steps(&r, 3);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.fallback == RPAS_FB_NONE);
    r.nav.flags &= ~(uint32_t)RPAS_NAV_AHRS;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.fallback == RPAS_FB_NAV_INVALID);
    CHECK_NEAR(r.cmd.ail, 0.0, 0.0);
    CHECK_NEAR(r.cmd.rud, 0.0, 0.0);
}

/* Heading errors take the short way round, across north and across 180. */
static void test_heading_wrap(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 10.0, 3000.0, 100.0);
    r.nav.hdg_deg = 350.0;
    steps(&r, 20);
    CHECK(r.fcs.bank_cmd > 5.0); /* right turn */
    CHECK(r.cmd.ail > 0.0);

    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 350.0, 3000.0, 100.0);
    r.nav.hdg_deg = 10.0;
    steps(&r, 20);
    CHECK(r.fcs.bank_cmd < -5.0); /* left turn */
    CHECK(r.cmd.ail < 0.0);

    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, -179.0, 3000.0, 100.0); /* = 181 */
    r.nav.hdg_deg = 179.0;
    steps(&r, 20);
    CHECK_NEAR(r.st.tgt_hdg_deg, 181.0, 1e-9);
    CHECK(r.fcs.bank_cmd > 0.0);

    /* track mode flies the GPS track, not the heading */
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    r.in.pilot.lat_mode = RPAS_LAT_TRK;
    r.nav.hdg_deg = 90.0;
    r.nav.trk_deg = 80.0; /* drifting left of the desired track */
    steps(&r, 20);
    CHECK(r.fcs.bank_cmd > 5.0);
}

/* Bank, pitch and surface limits hold whatever the errors. */
static void test_limits(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    const fcs_params_t *p = &r.fcs.prm;
    set_pilot_targets(&r, 270.0, 20000.0, 125.0); /* 180 deg away, 17000 ft up */
    double bank_max = 0.0;
    for (int i = 0; i < 200; i++) {
        step(&r);
        bank_max = fmax(bank_max, fabs(r.fcs.bank_cmd));
        CHECK(cmd_in_range(&r.cmd));
        CHECK(fabs(r.cmd.ail) <= p->ail_max + 1e-12);
        CHECK(fabs(r.cmd.elev) <= p->elev_max + 1e-12);
        CHECK(fabs(r.cmd.rud) <= p->rud_max + 1e-12);
    }
    CHECK_NEAR(bank_max, p->bank_max, 1e-9);
    /* the vertical speed command is the capture limit, the pitch command within its limits */
    CHECK_NEAR(r.fcs.vs_cmd, p->alt_vs_max, 1e-9);
    /* bank command rate limit: from 0 to 25 deg takes 25/8 s */
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 180.0, 3000.0, 100.0);
    steps(&r, 20); /* 1 s */
    CHECK_NEAR(r.fcs.bank_cmd, p->bank_rate * 1.0, 1e-6);
    /* an attitude pitched up beyond the protection limit: nose-down elevator */
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 9000.0, 100.0);
    r.nav.pitch_deg = 25.0;
    steps(&r, 5);
    CHECK(r.cmd.elev > 0.0);
    CHECK(r.st.env_flags & FCS_ENV_PITCH);
    /* an attitude banked beyond the autopilot protection limit: aileron against it */
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 180.0, 3000.0, 100.0);
    r.nav.roll_deg = 40.0;
    steps(&r, 5);
    CHECK(r.cmd.ail < 0.0);
    CHECK(r.st.env_flags & FCS_ENV_BANK);
}

/* A long saturation does not wind the integrators up: they stop where the output saturates
 * (conditional integration), so the output leaves saturation as soon as the error reverses. */
static void test_anti_windup(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 3000.0, 110.0);
    r.nav.ias_kt = 80.0; /* far too slow: throttle saturates */
    steps(&r, 600);
    CHECK_NEAR(r.cmd.thr, 1.0, 1e-12);
    double thr_i = r.fcs.thr_i;
    steps(&r, 1200); /* another minute saturated: the integrator has not moved */
    CHECK_NEAR(r.fcs.thr_i, thr_i, 1e-12);
    CHECK(thr_i < r.fcs.prm.thr_i_max); /* it stopped before its own limit */
    r.nav.ias_kt = 115.0; /* now too fast: the throttle comes back at once */
    step(&r);
    CHECK(r.cmd.thr < 0.8);

    /* elevator: a pitch that does not follow (stuck at -10 deg) */
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    r.nav.pitch_deg = -10.0;
    steps(&r, 600);
    CHECK(r.cmd.elev <= -r.fcs.prm.elev_max + 1e-9); /* full autopilot nose-up */
    double pitch_i = r.fcs.pitch_i, vs_i = r.fcs.vs_i;
    steps(&r, 1200);
    CHECK_NEAR(r.fcs.pitch_i, pitch_i, 1e-12);
    CHECK_NEAR(r.fcs.vs_i, vs_i, 1e-12);
    CHECK(pitch_i < r.fcs.prm.pitch_i_max);
    r.nav.pitch_deg = 2.0; /* the pitch follows again, a little above the command */
    step(&r);
    CHECK(r.cmd.elev > -r.fcs.prm.elev_max + 0.2);
}

/* DIRECT -> AUTOPILOT: the first autopilot command equals the surfaces' positions (in a
 * steady state: exactly; manoeuvring: within one step of loop action). */
static void test_bumpless_entry(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_DIRECT);
    r.in.pilot.stk_pitch = 0.12; /* elevator -0.12 */
    r.in.pilot.stk_roll = 0.05;
    r.in.pilot.stk_thr = 0.64;
    steps(&r, 40);
    CHECK(r.st.mode == RPAS_MODE_DIRECT);
    double e = r.cmd.elev, a = r.cmd.ail, t = r.cmd.thr;
    r.in.pilot.mode = RPAS_MODE_AUTOPILOT;
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT);
    CHECK_NEAR(r.cmd.elev, e, 1e-6);
    CHECK_NEAR(r.cmd.ail, a, 1e-6);
    CHECK_NEAR(r.cmd.thr, t, 1e-6);

    rig_init(&r, RPAS_MODE_DIRECT);
    r.in.pilot.stk_pitch = 0.12;
    r.in.pilot.stk_roll = 0.05;
    r.in.pilot.stk_thr = 0.64;
    r.nav.roll_deg = 3.0;
    r.nav.vs_fpm = 150.0;
    r.nav.ias_kt = 95.0;
    steps(&r, 40);
    e = r.cmd.elev, a = r.cmd.ail, t = r.cmd.thr;
    r.in.pilot.mode = RPAS_MODE_AUTOPILOT;
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    step(&r);
    CHECK_NEAR(r.cmd.elev, e, 0.03);
    CHECK_NEAR(r.cmd.ail, a, 0.03);
    CHECK_NEAR(r.cmd.thr, t, 0.03);

    /* AUTOPILOT -> DIRECT: the stick takes over over one second, not in one step */
    double e_ap = r.cmd.elev;
    r.in.pilot.mode = RPAS_MODE_DIRECT;
    r.in.pilot.stk_pitch = -0.6; /* push: elevator +0.6 */
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_DIRECT);
    CHECK(fabs(r.cmd.elev - e_ap) < 0.1);
    steps(&r, 20);
    CHECK_NEAR(r.cmd.elev, 0.6, 1e-9);
}

static void test_speed_protection_autopilot(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    steps(&r, 40);
    double elev_normal = r.cmd.elev;
    r.nav.ias_kt = 52.0;
    steps(&r, 10);
    CHECK(r.st.env_flags & FCS_ENV_UNDERSPEED);
    CHECK_NEAR(r.cmd.thr, 1.0, 1e-12);
    CHECK(r.cmd.elev > elev_normal + 0.05); /* nose down */
    r.nav.ias_kt = 150.0;
    steps(&r, 10);
    CHECK(r.st.env_flags & FCS_ENV_OVERSPEED);
    CHECK_NEAR(r.cmd.thr, r.fcs.prm.thr_min, 1e-12);
    CHECK(r.cmd.elev < elev_normal - 0.05); /* nose up */
}

static void test_bad_inputs_stay_finite(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, NAN, INFINITY, NAN);
    r.in.pilot.lat_mode = 7;
    r.in.pilot.vert_mode = 9;
    steps(&r, 20);
    CHECK(cmd_in_range(&r.cmd));
    CHECK(isfinite(r.st.tgt_hdg_deg) && isfinite(r.st.tgt_alt_ft) && isfinite(r.st.tgt_ias_kt));
    CHECK(r.st.lat_mode == RPAS_LAT_HDG && r.st.vert_mode == RPAS_VERT_ALT);
    r.in.pilot.mode = RPAS_MODE_DIRECT;
    r.in.pilot.stk_pitch = NAN;
    r.in.pilot.stk_thr = NAN;
    steps(&r, 30);
    CHECK(cmd_in_range(&r.cmd));
    r.in.pilot.mode = 99; /* unknown mode: not a pilot message we use */
    steps(&r, 40);
    CHECK(cmd_in_range(&r.cmd));
}

/* Asked AUTOPILOT, link up (the station's stick comes at 20 Hz in every mode). */
static void rig_degraded(rig_t *r)
{
    rig_init(r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(r, 200.0, 3500.0, 105.0);
    r->stick = true;
    r->in.pilot.stk_thr = 0.66;
    r->in.pilot.stk_roll = 0.1;
    steps(r, 40);
}

/* Attitude lost under AUTOPILOT: DIRECT for the pilot, SENSOR_LOST; back to the autopilot,
 * bumpless, once the attitude has been good for sensor_reengage_s. */
static void test_attitude_lost_reverts_to_direct(void)
{
    rig_t r;
    rig_degraded(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_NONE);
    double elev_ap = r.cmd.elev;
    r.nav.flags &= ~(uint32_t)RPAS_NAV_AHRS;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_DIRECT);
    CHECK(r.st.req_mode == RPAS_MODE_AUTOPILOT);
    CHECK(r.st.fallback == RPAS_FB_SENSOR_LOST);
    CHECK(fabs(r.cmd.elev - elev_ap) < 0.05); /* the stick fades in from the last command */
    steps(&r, 25);
    CHECK_NEAR(r.cmd.ail, 0.1, 1e-12); /* the stick, no protection without attitude */
    CHECK_NEAR(r.cmd.thr, 0.66, 1e-12);
    CHECK(r.st.env_flags == 0);
    CHECK_NEAR(r.st.tgt_hdg_deg, 200.0, 1e-9); /* the targets it flew stay on the downlink */
    /* the attitude comes back: DIRECT for 2 s more, then the pilot's AUTOPILOT */
    r.nav.flags |= RPAS_NAV_AHRS;
    steps(&r, 40); /* good since the first of them: 1.95 s at the last */
    CHECK(r.st.mode == RPAS_MODE_DIRECT && r.st.fallback == RPAS_FB_SENSOR_LOST);
    double ail = r.cmd.ail, thr = r.cmd.thr;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.st.tgt_hdg_deg, 200.0, 1e-9);
    CHECK_NEAR(r.cmd.ail, ail, 0.03);
    CHECK_NEAR(r.cmd.thr, thr, 0.03);
}

/* Air data lost: DIRECT too, with the attitude protection still acting. */
static void test_air_data_lost_reverts_to_direct(void)
{
    rig_t r;
    rig_degraded(&r);
    r.nav.flags &= ~(uint32_t)RPAS_NAV_AIR;
    r.in.pilot.stk_roll = 1.0;
    steps(&r, 30);
    CHECK(r.st.mode == RPAS_MODE_DIRECT && r.st.fallback == RPAS_FB_SENSOR_LOST);
    r.nav.roll_deg = 50.0;
    step(&r);
    CHECK(r.cmd.ail < 0.0);
    CHECK(r.st.env_flags & FCS_ENV_BANK);
    /* a sensor that comes and goes every 0.5 s keeps DIRECT: no toggling at its rate */
    r.nav.roll_deg = 0.0;
    for (int i = 0; i < 12; i++) {
        if (i % 2)
            r.nav.flags |= RPAS_NAV_AIR;
        else
            r.nav.flags &= ~(uint32_t)RPAS_NAV_AIR;
        steps(&r, 10);
        CHECK(r.st.mode == RPAS_MODE_DIRECT);
    }
}

/* Degraded without a pilot: no DIRECT to hand over. Air data lost: AUTOPILOT holding the
 * state captured (C2_LOST, as DIRECT without link); attitude lost: the attitude-free commands.
 * The link back: DIRECT for the pilot. */
static void test_degraded_without_c2(void)
{
    rig_t r;
    rig_degraded(&r);
    r.nav.flags &= ~(uint32_t)RPAS_NAV_AIR;
    r.nav.hdg_deg = 133.0;
    r.nav.alt_ft = 3210.0;
    r.in.pilot_ok = false;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_C2_LOST);
    CHECK_NEAR(r.st.tgt_hdg_deg, 133.0, 1e-9);
    CHECK_NEAR(r.st.tgt_alt_ft, 3210.0, 1e-9);
    steps(&r, 20);
    CHECK(cmd_in_range(&r.cmd));
    r.nav.flags &= ~(uint32_t)RPAS_NAV_AHRS;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_NAV_INVALID);
    CHECK_NEAR(r.cmd.ail, 0.0, 0.0);
    r.in.pilot_ok = true;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_DIRECT && r.st.fallback == RPAS_FB_SENSOR_LOST);
    /* the stick stops while the link is up: the same as no link */
    r.stick = false;
    r.in.pilot.t_stick_ns = r.now - 2000 * MS;
    r.nav.flags |= RPAS_NAV_AHRS;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_C2_LOST);
}

/* DIRECT asked: a lost sensor changes nothing but the protection it feeds. */
static void test_degraded_in_direct(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_DIRECT);
    r.in.pilot.stk_roll = 0.2;
    steps(&r, 30);
    r.nav.flags &= ~(uint32_t)(RPAS_NAV_AHRS | RPAS_NAV_AIR);
    steps(&r, 5);
    CHECK(r.st.mode == RPAS_MODE_DIRECT && r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.cmd.ail, 0.2, 1e-12);
    /* the link lost too: the attitude-free commands (nothing else can fly) */
    r.in.pilot_ok = false;
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_NAV_INVALID);
}

/* At the start a sensor not yet heard is not lost until sensor_wait_s; one never heard is. */
static void test_degraded_at_start(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    r.stick = true;
    r.nav.flags = RPAS_NAV_GPS | RPAS_NAV_AHRS; /* air data a little late */
    steps(&r, 10);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_NONE);
    r.nav.flags |= RPAS_NAV_AIR;
    steps(&r, 40);
    CHECK(r.st.mode == RPAS_MODE_AUTOPILOT && r.st.fallback == RPAS_FB_NONE);

    rig_init(&r, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&r, 90.0, 3000.0, 100.0);
    r.stick = true;
    r.nav.flags = RPAS_NAV_GPS | RPAS_NAV_AIR; /* no attitude, ever */
    steps(&r, 20); /* 0.95 s after the first step */
    CHECK(r.st.mode == RPAS_MODE_INIT && r.st.fallback == RPAS_FB_NAV_INVALID);
    step(&r);
    CHECK(r.st.mode == RPAS_MODE_DIRECT && r.st.fallback == RPAS_FB_SENSOR_LOST);
}

/* MISSION: a lost attitude hands the aircraft to the pilot; the mission resumes after. */
static void test_degraded_in_mission(void)
{
    rig_t r;
    rig_init(&r, RPAS_MODE_MISSION);
    r.stick = true;
    set_mission(&r, RPAS_MODE_MISSION, 45.0, 3500.0, 95.0);
    mission_steps(&r, 10, true);
    CHECK(r.st.mode == RPAS_MODE_MISSION);
    r.nav.flags &= ~(uint32_t)RPAS_NAV_AHRS;
    mission_steps(&r, 10, true);
    CHECK(r.st.mode == RPAS_MODE_DIRECT && r.st.fallback == RPAS_FB_SENSOR_LOST);
    CHECK(r.st.req_mode == RPAS_MODE_MISSION);
    r.nav.flags |= RPAS_NAV_AHRS;
    mission_steps(&r, 41, true);
    CHECK(r.st.mode == RPAS_MODE_MISSION && r.st.fallback == RPAS_FB_NONE);
    CHECK_NEAR(r.st.tgt_hdg_deg, 45.0, 1e-9);
}

/* Same inputs, same outputs: two replicas agree bit for bit. */
static void test_deterministic_replicas(void)
{
    rig_t a, b;
    rig_init(&a, RPAS_MODE_AUTOPILOT);
    rig_init(&b, RPAS_MODE_AUTOPILOT);
    set_pilot_targets(&a, 180.0, 3500.0, 105.0);
    set_pilot_targets(&b, 180.0, 3500.0, 105.0);
    for (int i = 0; i < 200; i++) {
        a.nav.roll_deg = b.nav.roll_deg = 10.0 * sin(i * 0.05);
        a.nav.vs_fpm = b.nav.vs_fpm = 100.0 * cos(i * 0.03);
        step(&a);
        step(&b);
        CHECK(memcmp(&a.cmd, &b.cmd, sizeof a.cmd) == 0);
        CHECK(memcmp(&a.st, &b.st, sizeof a.st) == 0);
    }
}

int main(void)
{
    RUN(test_direct_maps_stick);
    RUN(test_direct_envelope_protection);
    RUN(test_c2_loss_in_direct);
    RUN(test_c2_loss_in_autopilot);
    RUN(test_autopilot_without_targets_holds);
    RUN(test_mission_and_stale_fallback);
    RUN(test_nav_invalid);
    RUN(test_landing_flags_and_termination);
    RUN(test_heading_wrap);
    RUN(test_limits);
    RUN(test_anti_windup);
    RUN(test_bumpless_entry);
    RUN(test_speed_protection_autopilot);
    RUN(test_bad_inputs_stay_finite);
    RUN(test_deterministic_replicas);
    RUN(test_attitude_lost_reverts_to_direct);
    RUN(test_air_data_lost_reverts_to_direct);
    RUN(test_degraded_without_c2);
    RUN(test_degraded_in_direct);
    RUN(test_degraded_at_start);
    RUN(test_degraded_in_mission);
    return UNIT_RESULT();
}
