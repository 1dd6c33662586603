/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the mission manager's core: the CRC, plan checks, geometry (tracks, hold entry
 * sectors at each boundary, Dubins paths), and whole missions flown against a kinematic
 * aircraft (turn-rate and climb-rate limited, following the targets as nav_fcs would):
 * sequencing, fly-by turns, holds, termination by altitude, pilot commands, contingencies and
 * their resumption, the replicas' plan agreement, and determinism. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kinematic.h"
#include "rpas/unit_check.h"

/* ---- building plan images ------------------------------------------------------------- */

typedef struct {
    rpas_plan_header_t h;
    rpas_plan_leg_t leg[RPAS_PLAN_MAX_LEGS];
} image_t;

static int32_t e7(double deg)
{
    return (int32_t)lround(deg * 1e7);
}

/* A point `n`, `e` metres from the origin, as the plan's latitude and longitude. */
static void at(double n, double e, int32_t *lat, int32_t *lon)
{
    *lat = e7(LAT0 + n / (NF_DEG * NF_EARTH_R_M));
    *lon = e7(LON0 + e / (NF_DEG * NF_EARTH_R_M * cos(LAT0 * NF_DEG)));
}

static void image_init(image_t *im)
{
    memset(im, 0, sizeof *im);
    rpas_plan_header_t *h = &im->h;
    h->magic = RPAS_PLAN_MAGIC;
    h->version = RPAS_PLAN_VERSION;
    h->plan_id = 42;
    h->origin_lat_e7 = e7(LAT0);
    h->origin_lon_e7 = e7(LON0);
    h->cruise_ias_kt = 100.0f;
    h->cruise_alt_ft = 3000.0f;
    h->min_ias_kt = 65.0f;
    h->max_ias_kt = 125.0f;
    h->max_bank_deg = 25.0f;
    h->max_vs_fpm = 800.0f;
    h->traffic_h_m = 1000.0f;
    h->traffic_v_ft = 500.0f;
}

static rpas_plan_leg_t *add(image_t *im, int type, double n, double e)
{
    rpas_plan_leg_t *l = &im->leg[im->h.n_legs++];
    *l = (rpas_plan_leg_t){.type = (uint8_t)type, .course_deg = NAN, .alt_ft = NAN, .ias_kt = NAN,
                           .a = NAN, .b = NAN, .c = NAN, .d = NAN};
    at(n, e, &l->lat_e7, &l->lon_e7);
    return l;
}

static size_t image_len(const image_t *im)
{
    return sizeof im->h + im->h.n_legs * sizeof(rpas_plan_leg_t);
}

static uint32_t image_crc(const image_t *im)
{
    return rpas_crc32(im, image_len(im));
}

/* IF at the origin, TF 6 km east, TF 4 km south, TF back west. */
static void square(image_t *im)
{
    image_init(im);
    add(im, RPAS_LEG_IF, 0, 0);
    add(im, RPAS_LEG_TF, 0, 6000);
    add(im, RPAS_LEG_TF, -4000, 6000);
    add(im, RPAS_LEG_TF, -4000, 0);
    im->h.n_mission_legs = im->h.n_legs;
}

/* Runs the mission manager for `seconds`, the aircraft following it; returns cycles with
 * targets. `plan` (may be NULL) arrives in the first cycle. */
static int fly(mm_t *mm, ac_t *a, world_t *w, const image_t *plan, double seconds,
               rpas_mm_status_msg_t *st)
{
    int out = 0;
    for (int k = 0; k < (int)(seconds * 20.0); k++) {
        mm_inputs_t in;
        inputs(a, w, &in);
        if (plan && k == 0) {
            in.plan = plan;
            in.plan_len = image_len(plan);
            in.plan_crc = image_crc(plan);
        }
        rpas_mission_msg_t m;
        if (mm_step(mm, &in, a->t, &m, st)) {
            out++;
            ac_step(a, &m);
        } else {
            a->t += 50000000;
        }
    }
    return out;
}

/* A fresh mission manager and aircraft in a nominal world (the link up, GPS, the flight
 * control in MISSION, the plan agreed), given the plan and flown `seconds`. */
static void start(mm_t *mm, ac_t *a, world_t *w, const image_t *im, double seconds,
                  rpas_mm_status_msg_t *st)
{
    mm_init(mm, NULL);
    ac_init(a);
    *w = (world_t){.c2_up = true, .gps_ok = true, .fcs_mission = true, .agreed_crc = image_crc(im)};
    fly(mm, a, w, im, seconds, st);
}

/* ---- tests -------------------------------------------------------------------------------- */

static void test_crc32(void)
{
    CHECK(rpas_crc32("123456789", 9) == 0xCBF43926u);
    CHECK(rpas_crc32("", 0) == 0u);
}

static void test_plan_checks(void)
{
    image_t im;
    square(&im);
    mm_plan_t p;
    char err[80];
    CHECK(mm_plan_load(&p, &im, image_len(&im), image_crc(&im), err, sizeof err) == 0);
    CHECK(p.leg[1].has_from && fabs(p.leg[1].from.e) < 0.5);
    CHECK_NEAR(p.leg[1].next_crs, 180.0, 0.01); /* TF east, then south */
    CHECK(mm_plan_load(&p, &im, image_len(&im), image_crc(&im) ^ 1u, err, sizeof err) == -1);
    CHECK(strstr(err, "CRC") != NULL);
    CHECK(mm_plan_load(&p, &im, image_len(&im) - 1, rpas_crc32(&im, image_len(&im) - 1), err,
                       sizeof err) == -1);
    image_t bad = im;
    bad.h.magic = 0;
    CHECK(mm_plan_load(&p, &bad, image_len(&bad), image_crc(&bad), err, sizeof err) == -1);
    bad = im;
    bad.leg[2].type = 99;
    CHECK(mm_plan_load(&p, &bad, image_len(&bad), image_crc(&bad), err, sizeof err) == -1);
    CHECK(strstr(err, "leg 2") != NULL);
    bad = im;
    bad.h.contingency[RPAS_CT_C2_LOSS] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_PROCEDURE, .first_leg = 1, .n_legs = 1};
    CHECK(mm_plan_load(&p, &bad, image_len(&bad), image_crc(&bad), err, sizeof err) == -1);
    CHECK(strstr(err, "contingency 0") != NULL);
    bad = im;
    bad.leg[1].type = RPAS_LEG_CA; /* no altitude */
    CHECK(mm_plan_load(&p, &bad, image_len(&bad), image_crc(&bad), err, sizeof err) == -1);
}

static void test_track(void)
{
    mm_seg_t east = mm_line((mm_vec_t){0, 0}, (mm_vec_t){0, 1000});
    mm_track_t t = mm_track(&east, (mm_vec_t){-30, 400}); /* south of an eastbound path: right */
    CHECK_NEAR(t.xte_m, 30.0, 1e-9);
    CHECK_NEAR(t.along_m, 400.0, 1e-9);
    CHECK_NEAR(t.to_go_m, 600.0, 1e-9);
    mm_seg_t right = mm_arc((mm_vec_t){0, 0}, 1000.0, 1); /* clockwise */
    t = mm_track(&right, (mm_vec_t){1100, 0}); /* north of the centre, outside: left */
    CHECK_NEAR(t.path_crs, 90.0, 1e-9);
    CHECK_NEAR(t.xte_m, -100.0, 1e-9);
    mm_seg_t left = mm_arc((mm_vec_t){0, 0}, 1000.0, -1);
    t = mm_track(&left, (mm_vec_t){1100, 0});
    CHECK_NEAR(t.path_crs, 270.0, 1e-9);
    CHECK_NEAR(t.xte_m, 100.0, 1e-9);
    /* the guidance turns towards the path, never beyond chi_inf */
    mm_params_t prm;
    mm_params_default(&prm);
    t = mm_track(&east, (mm_vec_t){-5000, 0});
    double c = mm_lateral(&prm, &east, &t, 50.0);
    CHECK(nf_wrap180(c - 90.0) < 0.0 && nf_wrap180(c - 90.0) >= -prm.chi_inf_deg);
}

/* Every entry sector, 5 degrees either side of each boundary, right and left holds, for
 * several inbound courses. */
static void test_hold_entries(void)
{
    static const double inbound[] = {0.0, 90.0, 217.0, 355.0};
    for (unsigned i = 0; i < sizeof inbound / sizeof inbound[0]; i++) {
        for (int dir = -1; dir <= 1; dir += 2) {
            double c = inbound[i];
#define AT(rel) nf_wrap360(c + dir * (rel))
            CHECK(mm_hold_entry(AT(0.0), c, dir) == MM_ENTRY_DIRECT);
            CHECK(mm_hold_entry(AT(65.0), c, dir) == MM_ENTRY_DIRECT);
            CHECK(mm_hold_entry(AT(75.0), c, dir) == MM_ENTRY_PARALLEL);
            CHECK(mm_hold_entry(AT(175.0), c, dir) == MM_ENTRY_PARALLEL);
            CHECK(mm_hold_entry(AT(185.0), c, dir) == MM_ENTRY_TEARDROP);
            CHECK(mm_hold_entry(AT(245.0), c, dir) == MM_ENTRY_TEARDROP);
            CHECK(mm_hold_entry(AT(255.0), c, dir) == MM_ENTRY_DIRECT);
            CHECK(mm_hold_entry(AT(-60.0), c, dir) == MM_ENTRY_DIRECT);
#undef AT
        }
    }
}

static void test_dubins(void)
{
    mm_dubins_t d;
    /* straight ahead: no turns */
    CHECK(mm_dubins((mm_vec_t){0, 0}, 90.0, (mm_vec_t){0, 2000}, 90.0, 500.0, &d));
    CHECK_NEAR(d.length_m, 2000.0, 1e-6);
    /* a U-turn 2 km to the right: RSR, a quarter circle, 1 km, a quarter circle */
    CHECK(mm_dubins((mm_vec_t){0, 0}, 0.0, (mm_vec_t){0, 2000}, 180.0, 500.0, &d));
    CHECK_NEAR(d.length_m, 1000.0 + NF_PI * 500.0, 1e-6);
    CHECK(d.arc1.dir == 1 && d.arc2.dir == 1);
    CHECK_NEAR(d.t1.n, 500.0, 1e-6);
    CHECK_NEAR(d.t1.e, 500.0, 1e-6);
    /* an S-bend: RSL or LSR, never longer than the same-side words */
    CHECK(mm_dubins((mm_vec_t){0, 0}, 0.0, (mm_vec_t){3000, 2000}, 0.0, 500.0, &d));
    CHECK(d.arc1.dir == 1 && d.arc2.dir == -1);
    CHECK(d.length_m < hypot(3000.0, 2000.0) + NF_PI * 500.0);
}

static void test_square_mission(void)
{
    image_t im;
    square(&im);
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 1.0, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1 && st.leg_type == RPAS_LEG_TF);
    CHECK(st.plan_id == 42 && st.plan_crc == image_crc(&im));
    double worst = 0.0;
    int last_leg = 1;
    for (int k = 0; k < 20 * 500 && st.state == RPAS_MM_ACTIVE; k++) {
        fly(&mm, &a, &w, NULL, 0.05, &st);
        if (st.leg == last_leg && mm.ls.phase == 0 && !mm.ls.turning_in &&
            st.to_go_m < 0.8 * mm.ls.path_len_m)
            worst = fmax(worst, fabs(st.xte_m));
        last_leg = st.leg;
    }
    CHECK(st.state == RPAS_MM_COMPLETE);
    if (!(worst < 40.0))
        fprintf(stderr, "worst %.1f m\n", worst);
    CHECK(worst < 40.0);
    CHECK(fabs(a.n + 4000.0) < 300.0 && fabs(a.e) < 1500.0); /* orbiting the last fix */
}

static void test_no_plan_no_targets(void)
{
    mm_t mm;
    mm_init(&mm, NULL);
    ac_t a;
    ac_init(&a);
    world_t w = {.c2_up = true, .gps_ok = true, .fcs_mission = true};
    rpas_mm_status_msg_t st;
    CHECK(fly(&mm, &a, &w, NULL, 2.0, &st) == 0);
    CHECK(st.state == RPAS_MM_NO_PLAN && st.leg == -1);
    /* a plan that the replicas have not agreed on is held, not flown */
    image_t im;
    square(&im);
    CHECK(fly(&mm, &a, &w, &im, 2.0, &st) == 0);
    CHECK(st.state == RPAS_MM_NO_PLAN && mm.have_pending);
    w.agreed_crc = image_crc(&im);
    CHECK(fly(&mm, &a, &w, NULL, 1.0, &st) > 0);
    CHECK(st.state == RPAS_MM_ACTIVE);
    /* a corrupted plan is refused: the plan flown stays */
    image_t other = im;
    other.h.plan_id = 7;
    mm_inputs_t in;
    inputs(&a, &w, &in);
    in.plan = &other;
    in.plan_len = image_len(&other);
    in.plan_crc = image_crc(&other) ^ 0x10u;
    rpas_mission_msg_t m;
    mm_step(&mm, &in, a.t, &m, &st);
    CHECK(mm.rejected == 1 && st.plan_id == 42);
}

static void test_altitude_terminators(void)
{
    image_t im;
    image_init(&im);
    add(&im, RPAS_LEG_IF, 0, 0);
    rpas_plan_leg_t *ca = add(&im, RPAS_LEG_CA, 0, 0);
    ca->course_deg = 90.0f;
    ca->alt_ft = 3500.0f;
    rpas_plan_leg_t *va = add(&im, RPAS_LEG_VA, 0, 0);
    va->course_deg = 180.0f;
    va->alt_ft = 3000.0f;
    im.h.n_mission_legs = im.h.n_legs;
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 0.1, &st);
    CHECK(st.leg == 1);
    int k = 0;
    while (st.leg == 1 && k++ < 20 * 300)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.leg == 2);
    CHECK(fabs(a.alt - 3500.0) <= 50.0); /* CA ends at its altitude */
    while (st.leg == 2 && k++ < 20 * 600)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.state == RPAS_MM_COMPLETE);
    CHECK(fabs(a.alt - 3000.0) <= 50.0);
}

static void test_hold_circuits(void)
{
    image_t im;
    image_init(&im);
    add(&im, RPAS_LEG_IF, 0, 0);
    add(&im, RPAS_LEG_TF, 0, 4000);
    rpas_plan_leg_t *hm = add(&im, RPAS_LEG_HM, 0, 4000);
    hm->course_deg = 300.0f; /* arriving eastbound: 150 off the inbound course, parallel */
    hm->a = 40.0f;
    hm->count = 2;
    hm->flags = RPAS_LEG_TURN_RIGHT;
    im.h.n_mission_legs = im.h.n_legs;
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 0.1, &st);
    int k = 0;
    while (st.leg != 2 && k++ < 20 * 200)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    while (mm.ls.phase == 0 && k++ < 20 * 400)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    if (mm.ls.entry != MM_ENTRY_PARALLEL)
        fprintf(stderr, "entry %d trk %.1f\n", mm.ls.entry, a.trk);
    CHECK(mm.ls.entry == MM_ENTRY_PARALLEL);
    while (st.state == RPAS_MM_ACTIVE && k++ < 20 * 1500)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.state == RPAS_MM_COMPLETE);
    CHECK(mm.ls.leg == 2);
}

static void test_c2_loss_procedure_and_resume(void)
{
    image_t im;
    square(&im);
    im.h.n_mission_legs = im.h.n_legs;
    rpas_plan_leg_t *df = add(&im, RPAS_LEG_DF, 2000, 2000); /* the rally point */
    (void)df;
    rpas_plan_leg_t *orbit = add(&im, RPAS_LEG_ORBIT, 2000, 2000);
    orbit->a = 900.0f;
    orbit->flags = RPAS_LEG_TURN_RIGHT;
    im.h.contingency[RPAS_CT_C2_LOSS] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_PROCEDURE, .resume = 1, .first_leg = 4, .n_legs = 2,
        .detect_s = 2.0f, .continue_s = 10.0f};
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    rpas_mission_msg_t m;
    start(&mm, &a, &w, &im, 20.0, &st);
    CHECK(st.leg == 1);
    w.c2_up = false;
    int64_t lost = a.t;
    int k = 0;
    while (st.state != RPAS_MM_CONTINGENCY && k++ < 200)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    /* declared after its detection time, within one frame */
    CHECK(st.contingency == RPAS_CT_C2_LOSS);
    CHECK(llabs(a.t - lost - 2000000000LL) <= 100000000LL);
    /* the mission goes on for continue_s, then the procedure (DF to the rally point) */
    while (st.leg < 4 && k++ < 20 * 60)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.leg == 4 && st.leg_type == RPAS_LEG_DF);
    CHECK(llabs(a.t - lost - 12000000000LL) <= 100000000LL);
    while (st.leg != 5 && k++ < 20 * 600)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.leg == 5 && st.leg_type == RPAS_LEG_ORBIT);
    fly(&mm, &a, &w, NULL, 60.0, &st);
    CHECK(st.leg == 5); /* the procedure's last leg: it stays there */
    mm_inputs_t in;
    inputs(&a, &w, &in);
    mm_step(&mm, &in, a.t, &m, &st);
    CHECK(m.mode == RPAS_MODE_CONTINGENCY);
    /* the link is back: the mission resumes at the leg it left */
    w.c2_up = true;
    fly(&mm, &a, &w, NULL, 0.1, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1 && st.contingency == 255);
    inputs(&a, &w, &in);
    mm_step(&mm, &in, a.t, &m, &st);
    CHECK(m.mode == RPAS_MODE_MISSION);
}

/* A contingency preempting another's procedure: the mission resumes at the mission's leg. */
static void test_nested_contingencies(void)
{
    image_t im;
    square(&im);
    add(&im, RPAS_LEG_DF, 3000, 3000); /* the autopilot's procedure */
    add(&im, RPAS_LEG_DF, -3000, 3000); /* the link's */
    im.h.contingency[RPAS_CT_AP_DISENGAGE] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_PROCEDURE, .resume = 1, .first_leg = 4, .n_legs = 1, .detect_s = 1.0f};
    im.h.contingency[RPAS_CT_C2_LOSS] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_PROCEDURE, .resume = 1, .first_leg = 5, .n_legs = 1, .detect_s = 1.0f};
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 10.0, &st);
    CHECK(st.leg == 1);
    w.fcs_mode = RPAS_MODE_DIRECT;
    fly(&mm, &a, &w, NULL, 3.0, &st);
    CHECK(st.contingency == RPAS_CT_AP_DISENGAGE && st.leg == 4);
    w.c2_up = false;
    fly(&mm, &a, &w, NULL, 3.0, &st);
    CHECK(st.contingency == RPAS_CT_C2_LOSS && st.leg == 5);
    w.c2_up = true;
    w.fcs_mode = 0;
    fly(&mm, &a, &w, NULL, 0.2, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1 && st.contingency == 255);
}

static void test_gps_loss_hold_and_termination(void)
{
    image_t im;
    square(&im);
    im.h.contingency[RPAS_CT_GPS_LOSS] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_HOLD, .resume = 1, .detect_s = 1.0f};
    im.h.contingency[RPAS_CT_C2_LOSS] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_HOLD, .resume = 1, .detect_s = 1.0f};
    im.h.contingency[RPAS_CT_AP_DISENGAGE] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_HOLD, .resume = 1, .detect_s = 1.0f};
    im.h.contingency[RPAS_CT_TERMINATION] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_TERMINATE, .detect_s = 0.5f};
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 10.0, &st);
    w.gps_ok = false;
    fly(&mm, &a, &w, NULL, 1.1, &st);
    CHECK(st.state == RPAS_MM_CONTINGENCY && st.contingency == RPAS_CT_GPS_LOSS);
    CHECK(mm.flying_synth && mm.synth.raw.type == RPAS_LEG_ORBIT);
    w.gps_ok = true;
    fly(&mm, &a, &w, NULL, 0.1, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1);
    /* C2 loss, then the autopilot disengaged: flight termination, latched */
    w.c2_up = false;
    fly(&mm, &a, &w, NULL, 1.1, &st);
    CHECK(st.contingency == RPAS_CT_C2_LOSS);
    w.fcs_mode = RPAS_MODE_DIRECT;
    fly(&mm, &a, &w, NULL, 1.6, &st);
    CHECK(st.state == RPAS_MM_TERMINATED && st.contingency == RPAS_CT_TERMINATION);
    mm_inputs_t in;
    inputs(&a, &w, &in);
    rpas_mission_msg_t m;
    mm_step(&mm, &in, a.t, &m, &st);
    CHECK(m.flags & RPAS_MSN_TERMINATE);
    w.c2_up = true;
    w.fcs_mode = 0;
    fly(&mm, &a, &w, NULL, 5.0, &st);
    CHECK(st.state == RPAS_MM_TERMINATED);
}

static void test_traffic_avoidance(void)
{
    image_t im;
    square(&im);
    im.h.contingency[RPAS_CT_TRAFFIC] = (rpas_plan_contingency_t){
        .action = RPAS_CTA_AVOID, .resume = 1, .detect_s = 0.5f, .p1 = 60.0f, .p2 = 500.0f};
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 10.0, &st);
    double trk0 = a.trk;
    w.traffic = true; /* intruder ahead on the left (north-east), 100 ft below */
    fly(&mm, &a, &w, NULL, 0.6, &st);
    CHECK(st.contingency == RPAS_CT_TRAFFIC);
    fly(&mm, &a, &w, NULL, 30.0, &st);
    CHECK(nf_wrap180(a.trk - trk0) > 50.0); /* turned right, away from it */
    CHECK(a.alt > 3300.0);                   /* and climbed away from it */
    w.traffic = false;
    fly(&mm, &a, &w, NULL, 0.1, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1);
}

static void test_pilot_commands(void)
{
    image_t im;
    square(&im);
    mm_t mm;
    ac_t a;
    world_t w;
    rpas_mm_status_msg_t st;
    start(&mm, &a, &w, &im, 5.0, &st);
    w.cmd_seq = 1, w.cmd = RPAS_MMC_PAUSE;
    fly(&mm, &a, &w, NULL, 60.0, &st);
    CHECK(st.state == RPAS_MM_PAUSED);
    CHECK(hypot(a.n, a.e) < 3000.0); /* orbiting where it paused */
    w.cmd_seq = 2, w.cmd = RPAS_MMC_RESUME;
    fly(&mm, &a, &w, NULL, 0.1, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1);
    w.cmd_seq = 3, w.cmd = RPAS_MMC_DIRECT_TO, w.cmd_leg = 3;
    fly(&mm, &a, &w, NULL, 0.1, &st);
    CHECK(mm.flying_synth && mm.synth.raw.type == RPAS_LEG_DIRECT);
    int k = 0;
    while (mm.flying_synth && k++ < 20 * 300)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.state == RPAS_MM_COMPLETE); /* leg 3 was the last: direct to its fix, then done */
    CHECK(hypot(a.n + 4000.0, a.e) < 2000.0);
    /* engage: the plan again from its first leg, sequenced (the flight control flies it) */
    w.cmd_seq = 4, w.cmd = RPAS_MMC_ENGAGE;
    fly(&mm, &a, &w, NULL, 0.1, &st);
    CHECK(st.state == RPAS_MM_ACTIVE && st.leg == 1);
    k = 0;
    while (st.leg == 1 && k++ < 20 * 400)
        fly(&mm, &a, &w, NULL, 0.05, &st);
    CHECK(st.leg == 2 && st.state == RPAS_MM_ACTIVE);
}

/* An approach without an airspeed of its own, entered by a fly-by turn: every target nav_fcs
 * gets is finite (a NaN would make it drop the mission), the glide path is flown down and the
 * flare flagged. */
static void test_autoland_targets(void)
{
    image_t im;
    image_init(&im);
    add(&im, RPAS_LEG_IF, 0, 0);
    add(&im, RPAS_LEG_TF, -3000, 3000);
    rpas_plan_leg_t *land = add(&im, RPAS_LEG_AUTOLAND, -3000, 12000); /* the threshold */
    land->course_deg = 90.0f;
    land->alt_ft = 500.0f; /* the runway's elevation */
    land->a = 3.0f, land->b = 300.0f, land->c = 1500.0f, land->d = 30.0f;
    im.h.n_mission_legs = im.h.n_legs;
    mm_t mm;
    mm_init(&mm, NULL);
    ac_t a;
    ac_init(&a);
    a.alt = 1200.0;
    world_t w = {.c2_up = true, .gps_ok = true, .fcs_mission = true, .agreed_crc = image_crc(&im)};
    bool finite = true, approach = false, flare = false;
    double lowest = 1e9;
    for (int k = 0; k < 20 * 400; k++) {
        mm_inputs_t in;
        inputs(&a, &w, &in);
        if (k == 0) {
            in.plan = &im;
            in.plan_len = image_len(&im);
            in.plan_crc = image_crc(&im);
        }
        rpas_mission_msg_t m;
        rpas_mm_status_msg_t st;
        if (!mm_step(&mm, &in, a.t, &m, &st)) {
            a.t += 50000000;
            continue;
        }
        finite = finite && isfinite(m.hdg_deg) && isfinite(m.alt_ft) && isfinite(m.ias_kt) &&
                 isfinite(m.vs_fpm);
        approach = approach || (m.flags & RPAS_MSN_APPROACH);
        flare = flare || (m.flags & RPAS_MSN_FLARE);
        ac_step(&a, &m);
        lowest = fmin(lowest, a.alt);
    }
    CHECK(finite && approach && flare);
    CHECK(lowest < 540.0); /* down the glide path to the runway */
}

static void test_determinism(void)
{
    image_t im;
    square(&im);
    mm_t m1, m2;
    mm_init(&m1, NULL);
    mm_init(&m2, NULL);
    ac_t a;
    ac_init(&a);
    world_t w = {.c2_up = true, .gps_ok = true, .fcs_mission = true, .agreed_crc = image_crc(&im)};
    bool same = true;
    for (int k = 0; k < 20 * 400; k++) {
        mm_inputs_t in;
        inputs(&a, &w, &in);
        if (k == 0) {
            in.plan = &im;
            in.plan_len = image_len(&im);
            in.plan_crc = image_crc(&im);
        }
        rpas_mission_msg_t t1, t2;
        rpas_mm_status_msg_t s1, s2;
        memset(&t1, 0, sizeof t1);
        memset(&t2, 0, sizeof t2);
        bool o1 = mm_step(&m1, &in, a.t, &t1, &s1), o2 = mm_step(&m2, &in, a.t, &t2, &s2);
        same = same && o1 == o2 && !memcmp(&t1, &t2, sizeof t1) && !memcmp(&s1, &s2, sizeof s1);
        if (o1)
            ac_step(&a, &t1);
    }
    CHECK(same);
}

int main(void)
{
    RUN(test_crc32);
    RUN(test_plan_checks);
    RUN(test_track);
    RUN(test_hold_entries);
    RUN(test_dubins);
    RUN(test_square_mission);
    RUN(test_no_plan_no_targets);
    RUN(test_altitude_terminators);
    RUN(test_hold_circuits);
    RUN(test_c2_loss_procedure_and_resume);
    RUN(test_nested_contingencies);
    RUN(test_gps_loss_hold_and_termination);
    RUN(test_traffic_avoidance);
    RUN(test_pilot_commands);
    RUN(test_autoland_targets);
    RUN(test_determinism);
    return UNIT_RESULT();
}
