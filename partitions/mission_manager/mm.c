/* SPDX-License-Identifier: Apache-2.0 */
/* The mission layer: the plan (checked, activated only once every replica holds it), the
 * operational mode (MISSION, or CONTINGENCY while a contingency's procedure preempts the
 * leg), the pilot's commands (engage, pause, resume, direct-to), the contingencies (C2 link
 * loss, GPS loss, traffic, autopilot disengagement, and C2 loss followed by autopilot
 * disengagement: flight termination), and the resumption of the mission at the leg it left. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mm.h"
#include "nf_math.h"

#define NONE_CT RPAS_CT_COUNT

void mm_params_default(mm_params_t *p)
{
#define MM_PARAM_SET(name, value, meaning) p->name = (value);
    MM_PARAMS(MM_PARAM_SET)
#undef MM_PARAM_SET
}

const char *mm_state_name(uint32_t s)
{
    static const char *const n[] = {"NO_PLAN", "STANDBY", "ACTIVE", "PAUSED",
                                    "CONTINGENCY", "COMPLETE", "TERMINATED"};
    return s < sizeof n / sizeof n[0] ? n[s] : "?";
}

const char *mm_leg_name(int type)
{
    static const char *const n[] = {"?",  "IF", "TF", "DF", "CF", "RF", "CA", "FA", "VA",
                                    "HA", "HF", "HM", "DUBINS", "SCAN", "ORBIT", "DIRECT",
                                    "AUTOLAND"};
    return type >= 0 && type < (int)(sizeof n / sizeof n[0]) ? n[type] : "?";
}

const char *mm_ct_name(uint32_t c)
{
    static const char *const n[] = {"c2_loss", "gps_loss", "traffic", "autopilot_disengage",
                                    "flight_termination"};
    return c < RPAS_CT_COUNT ? n[c] : "none";
}

/* ---- the plan ------------------------------------------------------------------------------ */

static bool has_fix(int type)
{
    return type != RPAS_LEG_CA && type != RPAS_LEG_VA;
}

/* Where a leg leaves the aircraft, when a later leg may start from there. */
static bool end_point(const mm_leg_t *L, mm_vec_t *p)
{
    const rpas_plan_leg_t *r = &L->raw;
    switch (r->type) {
    case RPAS_LEG_CA:
    case RPAS_LEG_FA:
    case RPAS_LEG_VA:
    case RPAS_LEG_AUTOLAND:
        return false;
    case RPAS_LEG_SCAN: {
        int k = (r->count > 0 ? r->count : 1) - 1;
        int side = (r->flags & RPAS_LEG_TURN_LEFT) ? -1 : 1;
        mm_vec_t s = mm_add(L->fix, mm_vec(r->course_deg + 90.0 * side, r->b * k));
        *p = k % 2 ? s : mm_add(s, mm_vec(r->course_deg, r->a));
        return true;
    }
    default:
        *p = L->fix;
        return has_fix(r->type);
    }
}

/* The course on which leg `next` leaves the fix `at` (NaN: not known). */
static double leaving_course(const mm_leg_t *next, mm_vec_t at)
{
    const rpas_plan_leg_t *r = &next->raw;
    switch (r->type) {
    case RPAS_LEG_TF:
    case RPAS_LEG_DF:
        return mm_dist(at, next->fix) > 1.0 ? mm_course(at, next->fix) : NAN;
    case RPAS_LEG_CF:
    case RPAS_LEG_CA:
    case RPAS_LEG_FA:
    case RPAS_LEG_VA:
        return r->course_deg;
    case RPAS_LEG_RF:
        return nf_wrap360(mm_course(next->p2, at) + 90.0 * ((r->flags & RPAS_LEG_TURN_LEFT) ? -1 : 1));
    case RPAS_LEG_AUTOLAND: /* onto the final approach course */
        return r->course_deg;
    default:
        return NAN;
    }
}

static bool finite_f(float x)
{
    return isfinite(x);
}

/* A refused plan: why, with the leg or contingency (`which`, -1 none) it is about. */
static int bad(char *err, size_t errlen, const char *what, int which)
{
    if (which >= 0)
        snprintf(err, errlen, "%s %d", what, which);
    else
        snprintf(err, errlen, "%s", what);
    return -1;
}

/* What each type needs to be flown. */
static int check_leg(const rpas_plan_leg_t *r, int i, char *err, size_t errlen)
{
    if (r->type < RPAS_LEG_IF || r->type > RPAS_LEG_AUTOLAND)
        return bad(err, errlen, "unknown type: leg", i);
    bool course = r->type == RPAS_LEG_CF || r->type == RPAS_LEG_CA || r->type == RPAS_LEG_FA ||
                  r->type == RPAS_LEG_VA || r->type == RPAS_LEG_HA || r->type == RPAS_LEG_HF ||
                  r->type == RPAS_LEG_HM || r->type == RPAS_LEG_DUBINS ||
                  r->type == RPAS_LEG_SCAN || r->type == RPAS_LEG_AUTOLAND;
    if (course && !finite_f(r->course_deg))
        return bad(err, errlen, "no course: leg", i);
    bool needs_alt = r->type == RPAS_LEG_CA || r->type == RPAS_LEG_FA || r->type == RPAS_LEG_VA ||
                     r->type == RPAS_LEG_HA || r->type == RPAS_LEG_AUTOLAND;
    if (needs_alt && !finite_f(r->alt_ft))
        return bad(err, errlen, "no altitude: leg", i);
    if (r->type == RPAS_LEG_ORBIT && !(r->a > 50.0f))
        return bad(err, errlen, "orbit radius under 50 m: leg", i);
    if (r->type == RPAS_LEG_SCAN && !(r->a > 0.0f && r->b > 0.0f && r->count >= 1))
        return bad(err, errlen, "scan without a length, a spacing or passes: leg", i);
    if (r->type == RPAS_LEG_AUTOLAND && !(r->c >= 100.0f && r->b >= 0.0f && r->b < r->c))
        return bad(err, errlen, "runway length or aim point: leg", i);
    if (r->type == RPAS_LEG_RF && r->lat2_e7 == r->lat_e7 && r->lon2_e7 == r->lon_e7)
        return bad(err, errlen, "arc centre on the fix: leg", i);
    return 0;
}

int mm_plan_load(mm_plan_t *plan, const void *image, size_t len, uint32_t crc, char *err,
                 size_t errlen)
{
    const rpas_plan_header_t *h = image;
    if (len < sizeof *h)
        return bad(err, errlen, "shorter than a header", -1);
    if (rpas_crc32(image, len) != crc)
        return bad(err, errlen, "CRC mismatch", -1);
    if (h->magic != RPAS_PLAN_MAGIC || h->version != RPAS_PLAN_VERSION)
        return bad(err, errlen, "not a plan image of this version", -1);
    if (h->n_legs < 1 || h->n_legs > RPAS_PLAN_MAX_LEGS ||
        len != sizeof *h + h->n_legs * sizeof(rpas_plan_leg_t))
        return bad(err, errlen, "leg count and size disagree", -1);
    if (h->n_mission_legs < 1 || h->n_mission_legs > h->n_legs)
        return bad(err, errlen, "mission leg count", -1);
    if (!(h->min_ias_kt > 0.0f && h->max_ias_kt >= h->min_ias_kt && h->max_bank_deg >= 5.0f &&
          h->max_vs_fpm > 0.0f && finite_f(h->cruise_ias_kt) && finite_f(h->cruise_alt_ft)))
        return bad(err, errlen, "envelope", -1);
    for (int c = 0; c < RPAS_CT_COUNT; c++) {
        const rpas_plan_contingency_t *ct = &h->contingency[c];
        if (ct->action == RPAS_CTA_NONE)
            continue;
        if (ct->action > RPAS_CTA_TERMINATE || !(ct->detect_s >= 0.0f) || !(ct->continue_s >= 0.0f))
            return bad(err, errlen, "bad action or times: contingency", c);
        if (ct->action == RPAS_CTA_PROCEDURE &&
            (ct->n_legs < 1 || ct->first_leg < h->n_mission_legs ||
             ct->first_leg + ct->n_legs > h->n_legs))
            return bad(err, errlen, "procedure legs outside the plan: contingency", c);
    }
    memset(plan, 0, sizeof *plan);
    memcpy(&plan->hdr, h, sizeof *h);
    mm_frame_init(&plan->frame, h->origin_lat_e7 * 1e-7, h->origin_lon_e7 * 1e-7);
    const rpas_plan_leg_t *legs = (const rpas_plan_leg_t *)((const unsigned char *)image + sizeof *h);
    for (int i = 0; i < h->n_legs; i++) {
        mm_leg_t *L = &plan->leg[i];
        memcpy(&L->raw, &legs[i], sizeof L->raw);
        if (check_leg(&L->raw, i, err, errlen))
            return -1;
        L->fix = mm_from_e7(&plan->frame, L->raw.lat_e7, L->raw.lon_e7);
        L->p2 = mm_from_e7(&plan->frame, L->raw.lat2_e7, L->raw.lon2_e7);
        L->next_crs = NAN;
    }
    /* the previous fix of each leg, section by section (the mission, each procedure) */
    for (int i = 0; i < h->n_legs; i++) {
        bool section_start = i == 0 || i == h->n_mission_legs;
        for (int c = 0; c < RPAS_CT_COUNT; c++)
            if (h->contingency[c].action == RPAS_CTA_PROCEDURE && h->contingency[c].first_leg == i)
                section_start = true;
        mm_vec_t p;
        if (!section_start && end_point(&plan->leg[i - 1], &p)) {
            plan->leg[i].from = p;
            plan->leg[i].has_from = true;
            plan->leg[i - 1].next_crs = leaving_course(&plan->leg[i], p);
        }
    }
    plan->crc = crc;
    plan->loaded = true;
    return 0;
}

/* ---- the mission layer ------------------------------------------------------------------- */

void mm_init(mm_t *mm, const mm_params_t *prm)
{
    memset(mm, 0, sizeof *mm);
    if (prm)
        mm->prm = *prm;
    else
        mm_params_default(&mm->prm);
    mm->state = RPAS_MM_NO_PLAN;
    mm->ct_active = NONE_CT;
    mm->ls.leg = -1;
    mm->ls.flyby_crs = NAN;
    for (int c = 0; c < RPAS_CT_COUNT; c++)
        mm->cond_since[c] = -1;
}

static double age_s(int64_t now, int64_t t)
{
    return (double)(now - t) * 1e-9;
}

/* The last state change, for the partition to report. */
#define EVENT(...) snprintf(mm->event, sizeof mm->event, __VA_ARGS__)

static const mm_leg_t *leg_of(const mm_t *mm)
{
    return mm->flying_synth ? &mm->synth : &mm->plan.leg[mm->ls.leg];
}

/* Leg i from the present state; `flyby`: the leg before ended early to turn onto it. */
static void start_leg(mm_t *mm, int i, const mm_state_t *st, bool flyby)
{
    if (!flyby)
        mm->ls.flyby_crs = NAN;
    mm->flying_synth = false;
    mm->ls.leg = i;
    mm_leg_start(&mm->ls, &mm->plan.leg[i], &mm->plan.hdr, &mm->prm, st, mm->alt_ref_ft);
}

/* A leg made up in flight: `type` about/at position p. */
static void start_synth(mm_t *mm, int type, mm_vec_t p, double course, double alt,
                        const mm_state_t *st)
{
    int keep = mm->ls.leg;
    mm->synth = (mm_leg_t){.fix = p, .next_crs = NAN};
    mm->synth.raw = (rpas_plan_leg_t){.type = (uint8_t)type, .course_deg = (float)course,
                                      .alt_ft = (float)alt, .ias_kt = NAN,
                                      .flags = RPAS_LEG_TURN_RIGHT | RPAS_LEG_FLY_OVER};
    if (type == RPAS_LEG_ORBIT)
        mm->synth.raw.a = (float)(1.2 * mm_turn_radius(fmax(st->tas_mps, st->gs_mps),
                                                       mm->prm.turn_bank_deg));
    mm->flying_synth = true;
    mm->ls.leg = keep;
    mm->ls.flyby_crs = NAN;
    mm_leg_start(&mm->ls, &mm->synth, &mm->plan.hdr, &mm->prm, st, mm->alt_ref_ft);
    mm->ls.leg = keep;
}

/* A direct to leg i's fix (a rejoin, a pilot's direct-to): then on with leg i + 1, by a
 * fly-by turn onto it. */
static void direct_to(mm_t *mm, int i, const mm_state_t *st)
{
    const mm_leg_t *L = &mm->plan.leg[i];
    start_synth(mm, RPAS_LEG_DIRECT, L->fix, 0.0,
                isfinite(L->raw.alt_ft) ? L->raw.alt_ft : mm->alt_ref_ft, st);
    mm->synth.raw.flags = 0;
    if (i + 1 < mm->plan.hdr.n_mission_legs)
        mm->synth.next_crs = leaving_course(&mm->plan.leg[i + 1], L->fix);
    mm->ls.leg = i;
}

/* The first leg after the plan's IFs, from `i` (flyby: see start_leg). */
static void sequence_from(mm_t *mm, int i, int end, const mm_state_t *st, bool flyby)
{
    while (i < end && mm->plan.leg[i].raw.type == RPAS_LEG_IF)
        i++;
    if (i >= end) {
        mm->state = mm->state == RPAS_MM_CONTINGENCY ? mm->state : RPAS_MM_COMPLETE;
        start_synth(mm, RPAS_LEG_ORBIT, st->pos, 0.0, mm->alt_ref_ft, st);
        if (mm->state == RPAS_MM_COMPLETE)
            EVENT("mission complete");
        return;
    }
    start_leg(mm, i, st, flyby);
}

static void activate(mm_t *mm, const mm_state_t *st)
{
    mm->plan = mm->pending;
    mm->have_pending = false;
    mm->state = RPAS_MM_STANDBY;
    mm->engaged = false;
    mm->ct_active = NONE_CT;
    mm->ct_flags = 0;
    for (int c = 0; c < RPAS_CT_COUNT; c++)
        mm->cond_since[c] = -1;
    mm->alt_ref_ft = isfinite(st->alt_ft) ? st->alt_ft : mm->plan.hdr.cruise_alt_ft;
    sequence_from(mm, 0, mm->plan.hdr.n_mission_legs, st, false);
    EVENT("plan %u active: %u legs, crc 0x%08x",
             (unsigned)mm->plan.hdr.plan_id, (unsigned)mm->plan.hdr.n_legs, (unsigned)mm->plan.crc);
}

static void rejoin(mm_t *mm, int i, const mm_state_t *st);

static void pilot_command(mm_t *mm, const rpas_mm_cmd_msg_t *c, const mm_state_t *st)
{
    if (mm->state == RPAS_MM_NO_PLAN || mm->state == RPAS_MM_TERMINATED)
        return;
    switch (c->cmd) {
    case RPAS_MMC_ENGAGE:
        mm->state = mm->engaged ? RPAS_MM_ACTIVE : RPAS_MM_STANDBY;
        mm->ct_active = NONE_CT;
        sequence_from(mm, 0, mm->plan.hdr.n_mission_legs, st, false);
        EVENT("engaged: from the first leg");
        break;
    case RPAS_MMC_PAUSE:
        if (mm->state == RPAS_MM_ACTIVE || mm->state == RPAS_MM_STANDBY) {
            mm->resume_leg = mm->ls.leg;
            mm->state = RPAS_MM_PAUSED;
            start_synth(mm, RPAS_LEG_ORBIT, st->pos, 0.0, mm->alt_ref_ft, st);
            EVENT("paused at leg %d", mm->resume_leg);
        }
        break;
    case RPAS_MMC_RESUME:
        if (mm->state == RPAS_MM_PAUSED) {
            mm->state = mm->engaged ? RPAS_MM_ACTIVE : RPAS_MM_STANDBY;
            rejoin(mm, mm->resume_leg, st);
            EVENT("resumed at leg %d", mm->resume_leg);
        }
        break;
    case RPAS_MMC_DIRECT_TO:
        if (c->leg < mm->plan.hdr.n_mission_legs && has_fix(mm->plan.leg[c->leg].raw.type) &&
            mm->plan.leg[c->leg].raw.type != RPAS_LEG_AUTOLAND &&
            mm->state != RPAS_MM_CONTINGENCY) {
            mm->state = mm->engaged ? RPAS_MM_ACTIVE : RPAS_MM_STANDBY;
            direct_to(mm, (int)c->leg, st); /* then the leg after it */
            EVENT("direct to leg %d", (int)c->leg);
        }
        break;
    default:
        break;
    }
}

/* The conditions of the contingencies this cycle. */
static uint32_t conditions(const mm_t *mm, const mm_inputs_t *in, const mm_state_t *st,
                           int64_t now)
{
    const rpas_plan_header_t *h = &mm->plan.hdr;
    uint32_t c = 0;
    /* the link: the pilot's last message, valid or not (the port keeps the last one) */
    if (age_s(now, in->pilot.t_ns) > mm->prm.c2_max_age_s)
        c |= 1u << RPAS_CT_C2_LOSS;
    if (in->nav_ok && !(in->nav.flags & RPAS_NAV_GPS))
        c |= 1u << RPAS_CT_GPS_LOSS;
    if (in->traffic_ok && in->traffic.valid &&
        age_s(now, in->traffic.t_ns) <= mm->prm.traffic_max_age_s) {
        if (hypot(in->traffic.dn_m, in->traffic.de_m) < h->traffic_h_m &&
            fabs(in->traffic.dalt_ft) < h->traffic_v_ft)
            c |= 1u << RPAS_CT_TRAFFIC;
    }
    /* the flight control no longer flies the autopilot: DIRECT, or without attitude */
    if (in->fcs_ok && mm->engaged &&
        (in->fcs.mode == RPAS_MODE_DIRECT || in->fcs.mode == RPAS_MODE_INIT ||
         in->fcs.fallback == RPAS_FB_SENSOR_LOST || in->fcs.fallback == RPAS_FB_NAV_INVALID))
        c |= 1u << RPAS_CT_AP_DISENGAGE;
    return c;
}

/* Declares the contingencies whose condition held for their detection time. */
static void detect(mm_t *mm, uint32_t cond, int64_t now, int64_t in_pilot_t)
{
    const rpas_plan_header_t *h = &mm->plan.hdr;
    uint32_t declared = 0;
    for (int c = 0; c < RPAS_CT_TERMINATION; c++) {
        if (!(cond & (1u << c))) {
            mm->cond_since[c] = -1;
            continue;
        }
        if (mm->cond_since[c] < 0) {
            /* C2 loss: since the link was last heard (the pilot's frames come at 20 Hz); any
             * other: since the previous cycle, the latest instant it did not hold (it began
             * after it: its detection time counts from the earliest it may have begun) */
            if (c == RPAS_CT_C2_LOSS && in_pilot_t > 0)
                mm->cond_since[c] = in_pilot_t;
            else
                mm->cond_since[c] = mm->prev_ns > 0 ? mm->prev_ns : now;
        }
        if (age_s(now, mm->cond_since[c]) + 1e-9 >= h->contingency[c].detect_s)
            declared |= 1u << c;
    }
    uint32_t both = (1u << RPAS_CT_C2_LOSS) | (1u << RPAS_CT_AP_DISENGAGE);
    if ((declared & both) == both) {
        if (mm->cond_since[RPAS_CT_TERMINATION] < 0)
            mm->cond_since[RPAS_CT_TERMINATION] = now;
        if (age_s(now, mm->cond_since[RPAS_CT_TERMINATION]) + 1e-9 >=
            h->contingency[RPAS_CT_TERMINATION].detect_s)
            declared |= 1u << RPAS_CT_TERMINATION;
    } else {
        mm->cond_since[RPAS_CT_TERMINATION] = -1;
    }
    mm->ct_flags = declared;
}

/* Priority: termination, traffic, C2 loss, GPS loss, autopilot disengagement. */
static int rank(uint32_t c)
{
    static const int r[RPAS_CT_COUNT + 1] = {2, 3, 1, 4, 0, 99};
    return r[c < RPAS_CT_COUNT ? c : RPAS_CT_COUNT];
}

static void preempt(mm_t *mm, uint32_t c, const mm_state_t *st, const mm_inputs_t *in)
{
    const rpas_plan_contingency_t *ct = &mm->plan.hdr.contingency[c];
    if (mm->ct_active == NONE_CT && mm->state != RPAS_MM_PAUSED)
        mm->resume_leg = mm->ls.leg; /* (a contingency preempting another keeps its leg) */
    mm->ct_active = c;
    mm->ct_t0_ns = st->t_ns;
    mm->proc_started = false;
    mm->state = ct->action == RPAS_CTA_TERMINATE ? RPAS_MM_TERMINATED : RPAS_MM_CONTINGENCY;
    if (ct->action == RPAS_CTA_AVOID) {
        /* turn away from the intruder's side, climb or descend away from its altitude */
        mm_vec_t rel_p = {in->traffic.dn_m, in->traffic.de_m};
        double rel = nf_wrap180(mm_course((mm_vec_t){0.0, 0.0}, rel_p) - st->trk_deg);
        double away = rel >= 0.0 ? -1.0 : 1.0; /* it is on the right: turn left */
        double dalt = in->traffic.dalt_ft <= 0.0 ? ct->p2 : -ct->p2;
        start_synth(mm, RPAS_LEG_VA, st->pos, st->trk_deg + away * ct->p1,
                    st->alt_ft + dalt, st);
        mm->proc_started = true;
    }
    EVENT("contingency %s declared at leg %d", mm_ct_name(c), mm->resume_leg);
}

/* A procedure or hold begins once the mission has gone on for the plan's continue_s. */
static void contingency_step(mm_t *mm, const mm_state_t *st)
{
    const rpas_plan_contingency_t *ct = &mm->plan.hdr.contingency[mm->ct_active];
    bool later = ct->action == RPAS_CTA_PROCEDURE || ct->action == RPAS_CTA_HOLD;
    if (later && !mm->proc_started && age_s(st->t_ns, mm->ct_t0_ns) + 1e-9 >= ct->continue_s) {
        mm->proc_started = true;
        if (!mm->flying_synth && mm->ls.leg < mm->plan.hdr.n_mission_legs)
            mm->resume_leg = mm->ls.leg; /* the mission went on meanwhile (not a procedure's) */
        if (ct->action == RPAS_CTA_HOLD) {
            start_synth(mm, RPAS_LEG_ORBIT, st->pos, 0.0, mm->alt_ref_ft, st);
            EVENT("contingency %s: procedure starts (mission leg %d left)",
                  mm_ct_name(mm->ct_active), mm->resume_leg);
            return;
        }

        EVENT("contingency %s: procedure starts (mission leg %d left)", mm_ct_name(mm->ct_active),
              mm->resume_leg);
        sequence_from(mm, ct->first_leg, ct->first_leg + ct->n_legs, st, false);
    }
}

/* Back to the mission at leg i, from wherever the aircraft is: a leg that ends at its fix
 * (TF, DF, CF, RF) directly to that fix, then on; any other leg flown again from its start
 * (holds, orbits, scans and landings join their own path). */
static void rejoin(mm_t *mm, int i, const mm_state_t *st)
{
    if (i < 0) { /* preempted before any leg: from the first */
        sequence_from(mm, 0, mm->plan.hdr.n_mission_legs, st, false);
        return;
    }
    const mm_leg_t *L = &mm->plan.leg[i];
    int t = L->raw.type;
    if (t == RPAS_LEG_TF || t == RPAS_LEG_DF || t == RPAS_LEG_CF || t == RPAS_LEG_RF) {
        direct_to(mm, i, st);
    } else {
        start_leg(mm, i, st, false);
    }
}

/* The contingency in force has cleared: back to the mission at the leg it left. */
static void resume(mm_t *mm, const mm_state_t *st)
{
    uint32_t c = mm->ct_active;
    mm->ct_active = NONE_CT;
    mm->state = RPAS_MM_ACTIVE;
    rejoin(mm, mm->resume_leg, st);
    EVENT("contingency %s cleared: mission resumes at leg %d", mm_ct_name(c), mm->resume_leg);
}

/* The leg done: the next of its section. */
static void next_leg(mm_t *mm, const mm_state_t *st)
{
    if (isfinite(leg_of(mm)->raw.alt_ft) && leg_of(mm)->raw.type != RPAS_LEG_AUTOLAND)
        mm->alt_ref_ft = leg_of(mm)->raw.alt_ft;
    if (leg_of(mm)->raw.type == RPAS_LEG_AUTOLAND) {
        mm->state = mm->state == RPAS_MM_CONTINGENCY ? mm->state : RPAS_MM_COMPLETE;
        return; /* stopped on the runway: stays so */
    }
    bool synth = mm->flying_synth;
    if (synth && mm->synth.raw.type != RPAS_LEG_DIRECT)
        return; /* holds and avoidance end with their event, not by themselves */
    int end = mm->plan.hdr.n_mission_legs;
    if (mm->state == RPAS_MM_CONTINGENCY) {
        const rpas_plan_contingency_t *ct = &mm->plan.hdr.contingency[mm->ct_active];
        if (mm->proc_started) {
            end = ct->first_leg + ct->n_legs;
            if (mm->ls.leg + 1 >= end) { /* the procedure's last leg: orbit where it ended */
                start_synth(mm, RPAS_LEG_ORBIT, st->pos, 0.0, mm->alt_ref_ft, st);
                return;
            }
        }
    }
    /* after a direct-to, a fly-by onto the next leg too */
    sequence_from(mm, mm->ls.leg + 1, end, st,
                  !synth || (mm->synth.raw.type == RPAS_LEG_DIRECT && isfinite(mm->synth.next_crs)));
}

static bool state_from_nav(const mm_t *mm, const mm_inputs_t *in, int64_t now, mm_state_t *st)
{
    const rpas_nav_msg_t *n = &in->nav;
    if (!in->nav_ok || !(n->flags & (RPAS_NAV_GPS | RPAS_NAV_DR)) || !isfinite(n->lat_deg) ||
        !isfinite(n->lon_deg) || !isfinite(n->alt_ft))
        return false;
    const mm_frame_t *f = mm->plan.loaded ? &mm->plan.frame : &mm->pending.frame;
    st->pos = mm_to_local(f, n->lat_deg, n->lon_deg);
    st->alt_ft = n->alt_ft;
    st->ias_kt = isfinite(n->ias_kt) ? n->ias_kt : 0.0;
    st->gs_mps = n->gs_kt * NF_KT_MPS;
    st->trk_deg = n->trk_deg;
    st->vs_fpm = n->vs_fpm;
    st->tas_mps = nf_tas_from_ias(st->ias_kt, st->alt_ft) * NF_KT_MPS;
    st->wind_mps = hypot(n->wind_n_kt, n->wind_e_kt) * NF_KT_MPS;
    st->wheels_agl_ft = in->radalt_ok && in->radalt.valid && isfinite(in->radalt.height_ft) &&
                                age_s(now, in->radalt.t_ns) <= mm->prm.radalt_max_age_s
                            ? in->radalt.height_ft
                            : NAN;
    st->t_ns = now;
    return true;
}

static void receive_plan(mm_t *mm, const mm_inputs_t *in)
{
    char err[80];
    if (mm->plan.loaded && in->plan_crc == mm->plan.crc)
        return; /* the plan flown, sent again */
    mm_plan_t candidate; /* a refused plan leaves the one waiting for agreement */
    if (mm_plan_load(&candidate, in->plan, in->plan_len, in->plan_crc, err, sizeof err)) {
        mm->rejected++;
        EVENT("plan refused: %s", err);
        return;
    }
    mm->pending = candidate;
    mm->have_pending = true;
    EVENT("plan %u received (crc 0x%08x): waiting for the replicas",
             (unsigned)mm->pending.hdr.plan_id, (unsigned)mm->pending.crc);
}

bool mm_step(mm_t *mm, const mm_inputs_t *in, int64_t now_ns, rpas_mission_msg_t *target,
             rpas_mm_status_msg_t *status)
{
    mm->event[0] = '\0';
    if (in->plan)
        receive_plan(mm, in);
    mm_state_t st;
    bool have_state = state_from_nav(mm, in, now_ns, &st);
    bool cmd_fresh = in->cmd_ok && age_s(now_ns, in->cmd.t_ns) <= mm->prm.cmd_max_age_s;
    if (have_state && mm->have_pending && cmd_fresh && in->cmd.plan_crc == mm->pending.crc)
        activate(mm, &st);

    bool out = false;
    if (mm->plan.loaded && have_state) {
        if (cmd_fresh && (!mm->have_cmd_seq || in->cmd.cmd_seq != mm->last_cmd_seq)) {
            if (mm->have_cmd_seq)
                pilot_command(mm, &in->cmd, &st);
            mm->have_cmd_seq = true;
            mm->last_cmd_seq = in->cmd.cmd_seq;
        }
        bool following = in->fcs_ok && (in->fcs.mode == RPAS_MODE_MISSION ||
                                        in->fcs.mode == RPAS_MODE_CONTINGENCY);
        if (following && !mm->engaged) {
            mm->engaged = true;
            if (mm->state == RPAS_MM_STANDBY)
                mm->state = RPAS_MM_ACTIVE;
        }
        /* once landed (an AUTOLAND ended the mission) nothing preempts the stop */
        bool landed = mm->state == RPAS_MM_COMPLETE && !mm->flying_synth &&
                      leg_of(mm)->raw.type == RPAS_LEG_AUTOLAND;
        if (mm->state != RPAS_MM_TERMINATED && !landed) {
            detect(mm, conditions(mm, in, &st, now_ns), now_ns, in->pilot.t_ns);
            uint32_t best = NONE_CT;
            for (uint32_t c = 0; c < RPAS_CT_COUNT; c++)
                if ((mm->ct_flags & (1u << c)) && mm->plan.hdr.contingency[c].action != RPAS_CTA_NONE &&
                    rank(c) < rank(best))
                    best = c;
            if (best != NONE_CT && rank(best) < rank(mm->ct_active))
                preempt(mm, best, &st, in);
            else if (mm->ct_active != NONE_CT && !(mm->ct_flags & (1u << mm->ct_active))) {
                if (mm->plan.hdr.contingency[mm->ct_active].resume)
                    resume(mm, &st);
            }
            if (mm->state == RPAS_MM_CONTINGENCY)
                contingency_step(mm, &st);
        }

        mm_demand_t d = {0};
        if (mm->state == RPAS_MM_TERMINATED) {
            d = (mm_demand_t){.crs_deg = st.trk_deg, .alt_ft = st.alt_ft - 1000.0,
                              .ias_kt = mm->plan.hdr.min_ias_kt};
        } else {
            mm_leg_step(&mm->ls, leg_of(mm), &mm->prm, &st, &d);
            if (mm->ls.note && !mm->event[0])
                EVENT("leg %d %s", mm->ls.leg, mm->ls.note);
            bool sequencing = mm->state == RPAS_MM_ACTIVE || mm->state == RPAS_MM_CONTINGENCY;
            if (mm->ls.done && sequencing)
                next_leg(mm, &st);
        }
        mm->last = d;
        uint32_t mode = mm->state == RPAS_MM_CONTINGENCY || mm->state == RPAS_MM_TERMINATED
                            ? RPAS_MODE_CONTINGENCY
                            : RPAS_MODE_MISSION;
        memset(target, 0, sizeof *target);
        mm_guidance(&mm->prm, &mm->plan.hdr, &st, &d, mode, target);
        if (leg_of(mm)->raw.type == RPAS_LEG_AUTOLAND && !mm->flying_synth) {
            static const uint32_t f[] = {RPAS_MSN_APPROACH, RPAS_MSN_FLARE, RPAS_MSN_ROLLOUT,
                                         RPAS_MSN_ROLLOUT};
            target->flags = f[mm->ls.phase & 3];
            if (isfinite(d.ias_kt)) /* the approach's own speeds, under the cruise envelope */
                target->ias_kt = d.ias_kt;
        }
        if (mm->state == RPAS_MM_TERMINATED)
            target->flags = RPAS_MSN_TERMINATE;
        target->t_ns = now_ns;
        out = true;
    }

    memset(status, 0, sizeof *status);
    status->t_ns = now_ns;
    status->state = mm->state;
    status->contingency = mm->ct_active == NONE_CT ? 255u : mm->ct_active;
    status->ct_flags = mm->ct_flags;
    status->plan_id = mm->plan.loaded ? mm->plan.hdr.plan_id : 0;
    status->plan_crc = mm->plan.loaded ? mm->plan.crc : 0;
    status->leg = mm->plan.loaded ? mm->ls.leg : -1;
    status->leg_type = mm->plan.loaded ? leg_of(mm)->raw.type : 0;
    status->phase = (uint32_t)mm->ls.phase;
    status->to_go_m = mm->last.to_go_m;
    status->xte_m = mm->last.xte_m;
    status->alt_ref_ft = mm->last.alt_ft;
    mm->prev_ns = now_ns;
    return out;
}
