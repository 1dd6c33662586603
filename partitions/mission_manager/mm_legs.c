/* SPDX-License-Identifier: Apache-2.0 */
/* The sequencing layer: each leg of the plan as lateral manoeuvres (a straight on a course, an
 * arc of constant radius, a heading, a turn the way the procedure says) and vertical ones (a
 * level-off at the constraint, a climb or descent at constant airspeed, a geometric path), the
 * leg's phases (hold entries and circuits, scan passes, the Dubins arcs, the landing) and its
 * terminator: the fix (fly-by: the turn begins early enough to roll out on the next course;
 * fly-over: once over it), an altitude, a course, a number of circuits or a time. */
#include <math.h>

#include "mm.h"
#include "nf_math.h"

#define FT_PER_M 3.28084
#define OPEN_LINE_M 100000.0 /* a course flown until something else ends the leg */

enum hold_phase {
    H_ENTRY = 0,
    H_TURN1,     /* from inbound to outbound, over the fix end */
    H_OUTBOUND,
    H_TURN2,     /* from outbound to inbound */
    H_INBOUND,
    H_PAR_OUT,   /* parallel entry: outbound on the non-holding side */
    H_PAR_BACK,  /* ... turn back towards the holding side */
    H_PAR_TO_FIX,
    H_TD_OUT,    /* teardrop entry: 30 degrees off the outbound course, into the holding side */
    H_TD_BACK,
};

enum land_phase { L_FINAL = 0, L_FLARE, L_ROLLOUT, L_STOPPED };

/* DUBINS: the first arc, the straight, the last arc; or, too close for a Dubins path, direct */
enum dubins_phase { D_ARC1 = 0, D_LINE, D_ARC2, D_DIRECT };

static double turn_r(const mm_params_t *prm, const mm_state_t *st)
{
    return mm_turn_radius(fmax(st->gs_mps, st->tas_mps), prm->turn_bank_deg);
}

/* The distance before a fly-by fix at which the turn onto the next course begins. */
static double anticipation(const mm_leg_t *L, const mm_params_t *prm, const mm_state_t *st,
                           double crs)
{
    if ((L->raw.flags & RPAS_LEG_FLY_OVER) || !isfinite(L->next_crs))
        return 0.0;
    double delta = fabs(nf_wrap180(L->next_crs - crs));
    if (delta > 150.0)
        delta = 150.0;
    return turn_r(prm, st) * tan(delta * NF_DEG / 2.0);
}

/* Angle (deg) still to turn about centre c, turning dir, from p to the bearing `to`. */
static double arc_remaining(mm_vec_t c, mm_vec_t p, double to, int dir)
{
    return nf_wrap360((to - mm_course(c, p)) * dir);
}

static bool alt_reached(const mm_leg_state_t *ls, double target, double alt, double band)
{
    if (!isfinite(target))
        return true;
    return target >= ls->start_alt_ft ? alt >= target - band : alt <= target + band;
}

static int leg_dir(const rpas_plan_leg_t *r)
{
    return (r->flags & RPAS_LEG_TURN_LEFT) ? -1 : 1;
}

static void phase(mm_leg_state_t *ls, int p, mm_seg_t seg, const mm_state_t *st)
{
    ls->phase = p;
    ls->seg = seg;
    ls->phase_t0_ns = st->t_ns;
}

/* A turn the way `dir` says to `crs` (entries: the way the procedure turns, not the shorter). */
static mm_seg_t turn_to(double crs, int dir)
{
    return (mm_seg_t){.kind = MM_SEG_TURN, .crs = crs, .dir = dir};
}

static void hold_enter(mm_leg_state_t *ls, const mm_leg_t *L, const mm_state_t *st);

static void hold_setup(mm_leg_state_t *ls, const mm_leg_t *L, double r, double leg_m)
{
    int dir = leg_dir(&L->raw);
    double in = L->raw.course_deg;
    mm_vec_t side = mm_vec(in + 90.0 * dir, 1.0);
    mm_vec_t back = mm_vec(in, -leg_m);
    ls->rt_c1 = mm_add(L->fix, mm_scale(side, r));
    ls->rt_o0 = mm_add(L->fix, mm_scale(side, 2.0 * r));
    ls->rt_o1 = mm_add(ls->rt_o0, back);
    ls->rt_i0 = mm_add(L->fix, back);
    ls->rt_c2 = mm_add(ls->rt_i0, mm_scale(side, r));
}

void mm_leg_start(mm_leg_state_t *ls, const mm_leg_t *L, const rpas_plan_header_t *hdr,
                  const mm_params_t *prm, const mm_state_t *st, double alt_ref_ft)
{
    const rpas_plan_leg_t *r = &L->raw;
    double flyby = ls->flyby_crs;
    *ls = (mm_leg_state_t){.leg = ls->leg, .start = st->pos, .start_alt_ft = alt_ref_ft,
                           .phase_t0_ns = st->t_ns, .last_bearing = NAN, .flyby_crs = NAN};
    mm_vec_t from = L->has_from ? L->from : st->pos;
    switch (r->type) {
    case RPAS_LEG_IF:
        ls->done = true;
        ls->seg = mm_line(st->pos, L->fix);
        break;
    case RPAS_LEG_TF:
        ls->seg = mm_line(from, L->fix);
        break;
    case RPAS_LEG_DF:
    case RPAS_LEG_DIRECT:
        ls->seg = mm_line(st->pos, L->fix);
        break;
    case RPAS_LEG_CF: {
        double back = fmax(mm_dist(st->pos, L->fix), 2000.0);
        ls->seg = mm_line(mm_add(L->fix, mm_vec(r->course_deg, -back)), L->fix);
        break;
    }
    case RPAS_LEG_RF:
        ls->seg = mm_arc(L->p2, mm_dist(L->p2, L->fix), leg_dir(r));
        break;
    case RPAS_LEG_CA:
        ls->seg = mm_line(st->pos, mm_add(st->pos, mm_vec(r->course_deg, OPEN_LINE_M)));
        break;
    case RPAS_LEG_FA:
        ls->seg = mm_line(L->fix, mm_add(L->fix, mm_vec(r->course_deg, OPEN_LINE_M)));
        break;
    case RPAS_LEG_VA:
        ls->seg = (mm_seg_t){.kind = MM_SEG_HDG, .crs = r->course_deg};
        break;
    case RPAS_LEG_HA:
    case RPAS_LEG_HF:
    case RPAS_LEG_HM: {
        double ias = isfinite(r->ias_kt) ? r->ias_kt : hdr->cruise_ias_kt;
        double tas = nf_tas_from_ias(ias, st->alt_ft) * NF_KT_MPS;
        double leg_s = r->a > 0.0f ? r->a : prm->hold_default_leg_s;
        hold_setup(ls, L, mm_hold_radius(tas, prm->hold_rate_dps, hdr->max_bank_deg), tas * leg_s);
        ls->seg = mm_line(st->pos, L->fix);
        if (mm_dist(st->pos, L->fix) < 100.0) /* over the fix already: enter now */
            hold_enter(ls, L, st);
        break;
    }
    case RPAS_LEG_ORBIT:
        ls->seg = mm_arc(L->fix, r->a, leg_dir(r));
        ls->last_bearing = mm_course(L->fix, st->pos);
        break;
    case RPAS_LEG_SCAN:
        ls->seg = mm_line(L->fix, mm_add(L->fix, mm_vec(r->course_deg, r->a)));
        break;
    case RPAS_LEG_DUBINS: {
        double rad = r->a > 0.0f ? r->a : turn_r(prm, st);
        if (!mm_dubins(st->pos, st->trk_deg, L->fix, r->course_deg, rad, &ls->dubins)) {
            ls->seg = mm_line(st->pos, L->fix); /* too close for a Dubins path: direct */
            ls->phase = D_DIRECT;
            break;
        }
        ls->seg = ls->dubins.arc1;
        ls->arc_rem0 = arc_remaining(ls->dubins.arc1.c, st->pos,
                                     mm_course(ls->dubins.arc1.c, ls->dubins.t1), ls->dubins.arc1.dir);
        break;
    }
    case RPAS_LEG_AUTOLAND: {
        mm_vec_t far = mm_add(L->fix, mm_vec(r->course_deg, -20000.0));
        ls->seg = mm_line(far, mm_add(L->fix, mm_vec(r->course_deg, r->c)));
        break;
    }
    default:
        ls->done = true;
        break;
    }
    if (ls->seg.kind == MM_SEG_LINE)
        ls->path_len_m = mm_dist(ls->seg.a, ls->seg.b);
    /* the fly-by turn from the leg before onto this leg's straight */
    if (isfinite(flyby) && ls->seg.kind == MM_SEG_LINE && !ls->done) {
        double turn = nf_wrap180(ls->seg.crs - flyby);
        if (fabs(turn) > 2.0) {
            int dir = turn > 0.0 ? 1 : -1;
            ls->main = ls->seg;
            ls->turning_in = true;
            ls->seg = mm_arc(mm_add(st->pos, mm_vec(flyby + 90.0 * dir, turn_r(prm, st))),
                             turn_r(prm, st), dir);
            ls->seg.crs = ls->main.crs;
        }
    }
}

/* A straight leg ending at its fix: done at the fix, or earlier for a fly-by turn. */
static void to_fix(mm_leg_state_t *ls, const mm_leg_t *L, const mm_params_t *prm,
                   const mm_state_t *st, const mm_track_t *tk)
{
    double ant = anticipation(L, prm, st, ls->seg.crs);
    if (tk->to_go_m <= ant || tk->to_go_m <= 0.0) {
        ls->done = true;
        ls->flyby_crs = ant > 0.0 ? ls->seg.crs : NAN;
    }
}

/* Over the fix: the entry its track calls for. */
static void hold_enter(mm_leg_state_t *ls, const mm_leg_t *L, const mm_state_t *st)
{
    int dir = leg_dir(&L->raw);
    double in = L->raw.course_deg, out = nf_wrap360(in + 180.0);
    double rad = mm_dist(ls->rt_c1, L->fix);
    double leg_m = mm_dist(ls->rt_i0, L->fix);
    ls->entry = mm_hold_entry(st->trk_deg, in, dir);
    if (ls->entry == MM_ENTRY_DIRECT)
        phase(ls, H_TURN1, mm_arc(ls->rt_c1, rad, dir), st);
    else if (ls->entry == MM_ENTRY_PARALLEL)
        phase(ls, H_PAR_OUT, mm_line(L->fix, mm_add(L->fix, mm_vec(out, leg_m))), st);
    else
        phase(ls, H_TD_OUT, mm_line(L->fix, mm_add(L->fix, mm_vec(out - 30.0 * dir, leg_m))), st);
}

static void hold_step(mm_leg_state_t *ls, const mm_leg_t *L, const mm_params_t *prm,
                      const mm_state_t *st, const mm_track_t *tk, double alt_target)
{
    const rpas_plan_leg_t *r = &L->raw;
    int dir = leg_dir(r);
    double in = r->course_deg, out = nf_wrap360(in + 180.0);
    double rad = mm_dist(ls->rt_c1, L->fix);
    switch (ls->phase) {
    case H_ENTRY:
        if (tk->to_go_m <= 0.0)
            hold_enter(ls, L, st);
        break;
    case H_TURN1:
        if (arc_remaining(ls->rt_c1, st->pos, mm_course(ls->rt_c1, ls->rt_o0), dir) > 300.0 ||
            fabs(nf_wrap180(st->trk_deg - out)) < 10.0)
            phase(ls, H_OUTBOUND, mm_line(ls->rt_o0, ls->rt_o1), st);
        break;
    case H_OUTBOUND:
        if (tk->to_go_m <= 0.0)
            phase(ls, H_TURN2, mm_arc(ls->rt_c2, rad, dir), st);
        break;
    case H_TURN2:
        if (arc_remaining(ls->rt_c2, st->pos, mm_course(ls->rt_c2, ls->rt_i0), dir) > 300.0 ||
            fabs(nf_wrap180(st->trk_deg - in)) < 10.0)
            phase(ls, H_INBOUND, mm_line(ls->rt_i0, L->fix), st);
        break;
    case H_INBOUND:
        if (tk->to_go_m <= 0.0) {
            ls->laps++;
            bool end = (r->type == RPAS_LEG_HF && ls->laps >= 1) ||
                       (r->type == RPAS_LEG_HM && r->count > 0 && ls->laps >= r->count) ||
                       (r->type == RPAS_LEG_HA &&
                        fabs(st->alt_ft - alt_target) <= prm->alt_band_ft);
            if (end)
                ls->done = true;
            else
                phase(ls, H_TURN1, mm_arc(ls->rt_c1, rad, dir), st);
        }
        break;
    case H_PAR_OUT:
        if (tk->to_go_m <= 0.0)
            phase(ls, H_PAR_BACK, turn_to(in, -dir), st);
        break;
    case H_PAR_BACK:
        if (fabs(nf_wrap180(mm_course(st->pos, L->fix) - st->trk_deg)) < 45.0)
            phase(ls, H_PAR_TO_FIX, mm_line(st->pos, L->fix), st);
        break;
    case H_PAR_TO_FIX:
        if (tk->to_go_m <= 0.0)
            phase(ls, H_TURN1, mm_arc(ls->rt_c1, rad, dir), st);
        break;
    case H_TD_OUT:
        if (tk->to_go_m <= 0.0)
            phase(ls, H_TD_BACK, turn_to(in, dir), st);
        break;
    case H_TD_BACK:
        if (fabs(nf_wrap180(st->trk_deg - in)) < 60.0)
            phase(ls, H_INBOUND, mm_line(ls->rt_i0, L->fix), st);
        break;
    }
    /* the entry is flown once the racetrack's own phases begin */
    bool on_racetrack = ls->phase >= H_TURN1 && ls->phase <= H_INBOUND;
    if (on_racetrack && !ls->racetrack) {
        static const char *const names[] = {"hold: direct entry flown, on the racetrack",
                                            "hold: parallel entry flown, on the racetrack",
                                            "hold: teardrop entry flown, on the racetrack"};
        ls->racetrack = true;
        ls->note = names[ls->entry];
    }
}

static void dubins_step(mm_leg_state_t *ls, const mm_leg_t *L, const mm_state_t *st,
                        const mm_track_t *tk)
{
    const mm_dubins_t *d = &ls->dubins;
    if (ls->phase == D_ARC1) {
        double rem = arc_remaining(d->arc1.c, st->pos, mm_course(d->arc1.c, d->t1), d->arc1.dir);
        if (rem < 3.0 || rem > ls->arc_rem0 + 20.0)
            phase(ls, D_LINE, d->line, st);
    } else if (ls->phase == D_LINE) {
        if (tk->to_go_m <= 0.0)
            phase(ls, D_ARC2, d->arc2, st);
    } else if (ls->phase == D_ARC2) {
        double rem = arc_remaining(d->arc2.c, st->pos, mm_course(d->arc2.c, L->fix), d->arc2.dir);
        if (rem < 2.0 || rem > 300.0)
            ls->done = true;
    } else if (tk->to_go_m <= 0.0) {
        ls->done = true;
    }
}

static void scan_step(mm_leg_state_t *ls, const mm_leg_t *L, const mm_state_t *st,
                      const mm_track_t *tk)
{
    const rpas_plan_leg_t *r = &L->raw;
    if (tk->to_go_m > 0.0)
        return;
    if (++ls->pass >= (r->count > 0 ? r->count : 1)) {
        ls->done = true;
        return;
    }
    int side = (r->flags & RPAS_LEG_TURN_LEFT) ? -1 : 1;
    mm_vec_t s = mm_add(L->fix, mm_vec(r->course_deg + 90.0 * side, r->b * ls->pass));
    mm_vec_t e = mm_add(s, mm_vec(r->course_deg, r->a));
    phase(ls, ls->pass, ls->pass % 2 ? mm_line(e, s) : mm_line(s, e), st);
}

/* The automatic landing: the final on the glide path to the aim point, the flare, the
 * roll-out on the centre line to a stop. The height of the wheels from the radar altimeter
 * when it reports, else from the navigation altitude. */
static void land_step(mm_leg_state_t *ls, const mm_leg_t *L, const mm_params_t *prm,
                      const mm_state_t *st, const mm_track_t *tk, mm_demand_t *d)
{
    const rpas_plan_leg_t *r = &L->raw;
    double elev = r->alt_ft;
    double wheels = isfinite(st->wheels_agl_ft) ? st->wheels_agl_ft
                                                : st->alt_ft - elev - prm->gear_ft;
    double gp = (r->a > 0.0f ? r->a : 3.0) * NF_DEG;
    double to_aim = 20000.0 - tk->along_m + r->b; /* along the centre line to the aim point */
    double path = elev + prm->gear_ft + to_aim * tan(gp) * FT_PER_M;
    d->raw_vs = ls->phase != L_FINAL;
    d->centre_k = ls->phase == L_FLARE ? prm->flare_xte_k
                  : ls->phase != L_FINAL ? prm->runway_xte_k
                                         : 0.0;
    switch (ls->phase) {
    case L_FINAL:
        /* below the glide path: level at the leg's start altitude until it is intercepted */
        d->alt_ft = fmin(path, fmax(ls->start_alt_ft, elev + 200.0));
        d->vs_ff_fpm = path <= ls->start_alt_ft ? -st->gs_mps * tan(gp) * FT_PER_M * 60.0 : 0.0;
        if (wheels < prm->flare_ft && to_aim < 1500.0) {
            /* the flare takes over the sink rate it finds: h / tau + the touchdown sink */
            double sink = fmax(-st->vs_fpm / 60.0, prm->flare_sink_fps + 1.0);
            ls->flare_tau = fmax(prm->flare_tau_min_s, wheels / (sink - prm->flare_sink_fps));
            phase(ls, L_FLARE, ls->seg, st);
        }
        break;
    case L_FLARE:
        /* the sink rate falls with the height: an exponential path onto the runway; the
         * throttle at idle (nav_fcs), the airspeed decays */
        d->alt_ft = st->alt_ft;
        d->ias_kt = prm->flare_ias_kt;
        d->vs_ff_fpm = -60.0 * (fmax(wheels, 0.0) / ls->flare_tau + prm->flare_sink_fps);
        if (wheels < (isfinite(st->wheels_agl_ft) ? 0.5 : 1.0))
            phase(ls, L_ROLLOUT, ls->seg, st);
        break;
    case L_ROLLOUT:
        d->alt_ft = st->alt_ft;
        if (st->gs_mps < 0.5) {
            phase(ls, L_STOPPED, ls->seg, st);
            ls->done = true;
        }
        break;
    default:
        d->alt_ft = st->alt_ft;
        break;
    }
}

void mm_leg_step(mm_leg_state_t *ls, const mm_leg_t *L, const mm_params_t *prm,
                 const mm_state_t *st, mm_demand_t *d)
{
    const rpas_plan_leg_t *r = &L->raw;
    ls->note = NULL;
    if (ls->turning_in) {
        /* the fly-by arc ends where its course is the leg's (the tangent point) */
        double end = nf_wrap360(ls->main.crs - 90.0 * ls->seg.dir);
        double rem = arc_remaining(ls->seg.c, st->pos, end, ls->seg.dir);
        if (rem < 2.0 || rem > 300.0 || fabs(nf_wrap180(st->trk_deg - ls->main.crs)) < 3.0) {
            ls->turning_in = false;
            ls->seg = ls->main;
        }
    }
    mm_track_t tk = mm_track(&ls->seg, st->pos);
    bool land = r->type == RPAS_LEG_AUTOLAND; /* its alt_ft is the runway's elevation */
    double alt_target = isfinite(r->alt_ft) && !land ? r->alt_ft : ls->start_alt_ft;

    d->ias_kt = land && !isfinite(r->ias_kt) ? prm->approach_ias_kt : r->ias_kt;
    d->alt_ft = alt_target;
    d->vs_ff_fpm = 0.0;
    d->hdg = false;
    d->centre_k = 0.0;

    switch (ls->turning_in ? 0 : r->type) {
    case 0: /* the fly-by arc: the leg's terminator is on its straight */
        if (land) { /* the glide path is flown from the final's own line */
            mm_track_t on_final = mm_track(&ls->main, st->pos);
            land_step(ls, L, prm, st, &on_final, d);
        }
        break;
    case RPAS_LEG_TF:
    case RPAS_LEG_DF:
    case RPAS_LEG_DIRECT:
    case RPAS_LEG_CF:
        to_fix(ls, L, prm, st, &tk);
        break;
    case RPAS_LEG_RF: {
        double rem = arc_remaining(L->p2, st->pos, mm_course(L->p2, L->fix), ls->seg.dir);
        double ant = anticipation(L, prm, st, nf_wrap360(tk.path_crs));
        double ant_deg = ant / fmax(ls->seg.r, 1.0) / NF_DEG;
        if (rem < fmax(1.0, ant_deg) || rem > 330.0)
            ls->done = true;
        tk.to_go_m = rem * NF_DEG * ls->seg.r;
        break;
    }
    case RPAS_LEG_CA:
    case RPAS_LEG_FA:
    case RPAS_LEG_VA:
        if (alt_reached(ls, r->alt_ft, st->alt_ft, prm->alt_band_ft))
            ls->done = true;
        break;
    case RPAS_LEG_HA:
    case RPAS_LEG_HF:
    case RPAS_LEG_HM:
        hold_step(ls, L, prm, st, &tk, alt_target);
        break;
    case RPAS_LEG_ORBIT: {
        double b = mm_course(L->fix, st->pos);
        if (isfinite(ls->last_bearing)) {
            double step = nf_wrap180(b - ls->last_bearing) * ls->seg.dir;
            if (step > 0.0)
                ls->turned_deg += step;
        }
        ls->last_bearing = b;
        double t = (double)(st->t_ns - ls->phase_t0_ns) * 1e-9;
        if ((r->count > 0 && ls->turned_deg >= 360.0 * r->count) || (r->b > 0.0f && t >= r->b))
            ls->done = true;
        ls->laps = (int)(ls->turned_deg / 360.0);
        break;
    }
    case RPAS_LEG_SCAN:
        scan_step(ls, L, st, &tk);
        break;
    case RPAS_LEG_DUBINS:
        dubins_step(ls, L, st, &tk);
        break;
    case RPAS_LEG_AUTOLAND:
        land_step(ls, L, prm, st, &tk, d);
        break;
    default:
        ls->done = true;
        break;
    }
    /* the segment may have changed with the phase: the demand is on the segment now flown */
    mm_track_t now = mm_track(&ls->seg, st->pos);
    if (ls->seg.kind == MM_SEG_TURN) {
        d->crs_deg = nf_wrap360(st->trk_deg + 90.0 * ls->seg.dir);
    } else {
        d->crs_deg = mm_lateral(prm, &ls->seg, &now, st->gs_mps);
        d->hdg = ls->seg.kind == MM_SEG_HDG;
    }
    if (d->centre_k > 0.0 && !ls->turning_in)
        /* near and on the runway: the centre line held tightly, never more than 10 deg off */
        d->crs_deg = nf_wrap360(ls->seg.crs - nf_clamp(d->centre_k * now.xte_m, -10.0, 10.0));
    d->xte_m = ls->seg.kind == MM_SEG_LINE || ls->seg.kind == MM_SEG_ARC ? now.xte_m : 0.0;
    d->to_go_m = ls->seg.kind == MM_SEG_LINE ? now.to_go_m : tk.to_go_m;

    /* a geometric path: from the leg's start altitude to the constraint over the leg's length */
    if ((r->flags & RPAS_LEG_ALT_PATH) && isfinite(r->alt_ft) && ls->path_len_m > 1.0 &&
        r->type != RPAS_LEG_AUTOLAND) {
        /* along the leg's own straight, also while the fly-by arc onto it is flown */
        mm_track_t on_leg = ls->turning_in ? mm_track(&ls->main, st->pos) : now;
        double f = nf_clamp(on_leg.along_m / ls->path_len_m, 0.0, 1.0);
        double grad = (r->alt_ft - ls->start_alt_ft) / ls->path_len_m; /* ft per m */
        d->alt_ft = ls->start_alt_ft + (r->alt_ft - ls->start_alt_ft) * f;
        d->vs_ff_fpm = f < 1.0 ? grad * st->gs_mps * 60.0 : 0.0;
    }
}
