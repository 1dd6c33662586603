/* SPDX-License-Identifier: Apache-2.0 */
/* Flight-control core: mode and fallback logic, autopilot loops, envelope protection. */
#include "fcs.h"

#include <math.h>
#include <string.h>

#include "nf_math.h"

void fcs_default_params(fcs_params_t *prm)
{
#define FCS_PARAM_DEFAULT(name, def, doc) prm->name = def;
    FCS_PARAMS(FCS_PARAM_DEFAULT)
#undef FCS_PARAM_DEFAULT
}

void fcs_init(fcs_t *fcs, const fcs_params_t *prm)
{
    memset(fcs, 0, sizeof *fcs);
    if (prm)
        fcs->prm = *prm;
    else
        fcs_default_params(&fcs->prm);
    fcs->mode = RPAS_MODE_INIT;
    fcs->req_mode = RPAS_MODE_INIT;
    fcs->thr = fcs->prm.thr_ff;
    fcs->tgt.ias = 100.0;
    fcs->sensors_ok_since_ns = -1;
}

static double age_s(int64_t now_ns, int64_t t_ns)
{
    return (double)(now_ns - t_ns) * 1e-9;
}

static double finite_or(double x, double fallback)
{
    return isfinite(x) ? x : fallback;
}

static bool pilot_usable(const fcs_t *f, const fcs_inputs_t *in, int64_t now_ns)
{
    return in->pilot_ok && age_s(now_ns, in->pilot.t_ns) <= f->prm.pilot_max_age_s &&
           in->pilot.mode <= RPAS_MODE_CONTINGENCY;
}

static bool stick_fresh(const fcs_t *f, const fcs_inputs_t *in, bool pilot_now, int64_t now_ns)
{
    const rpas_pilot_msg_t *p = &in->pilot;
    return pilot_now && p->t_stick_ns != 0 && age_s(now_ns, p->t_stick_ns) <= f->prm.stick_max_age_s;
}

static bool mission_usable(const fcs_t *f, const fcs_inputs_t *in, int64_t now_ns)
{
    const rpas_mission_msg_t *m = &in->mission;
    return in->mission_ok && age_s(now_ns, m->t_ns) <= f->prm.mission_max_age_s &&
           (m->mode == RPAS_MODE_MISSION || m->mode == RPAS_MODE_CONTINGENCY) &&
           m->lat_mode <= RPAS_LAT_TRK && m->vert_mode <= RPAS_VERT_VS && isfinite(m->hdg_deg) &&
           isfinite(m->alt_ft) && isfinite(m->ias_kt) && isfinite(m->vs_fpm);
}

/* Targets as given, limited to what the loops may fly; a non-finite field keeps its old value. */
static fcs_targets_t sane_targets(const fcs_t *f, uint32_t lat, uint32_t vert, double hdg,
                                  double alt, double ias, double vs)
{
    const fcs_params_t *p = &f->prm;
    fcs_targets_t t;
    t.lat_mode = lat <= RPAS_LAT_TRK ? lat : RPAS_LAT_HDG;
    t.vert_mode = vert <= RPAS_VERT_VS ? vert : RPAS_VERT_ALT;
    t.hdg = nf_wrap360(finite_or(hdg, f->tgt.hdg));
    t.alt = nf_clamp(finite_or(alt, f->tgt.alt), -1000.0, 20000.0);
    t.ias = nf_clamp(finite_or(ias, f->tgt.ias), p->ias_min, p->ias_max);
    t.vs = nf_clamp(finite_or(vs, f->tgt.vs), -p->vs_max, p->vs_max);
    t.flags = 0;
    return t;
}

/* Targets that hold the present state: heading, altitude, airspeed. */
static fcs_targets_t capture_state(const fcs_t *f, const rpas_nav_msg_t *nav)
{
    double ias = (nav->flags & RPAS_NAV_AIR) ? nav->ias_kt : f->tgt.ias;
    return sane_targets(f, RPAS_LAT_HDG, RPAS_VERT_ALT, nav->hdg_deg, nav->alt_ft, ias, 0.0);
}

/* Attitude (AHRS) or air data unusable: the autopilot loops cannot be trusted. A source that
 * has never been seen counts as lost only sensor_wait_s after the start (the first samples
 * need a frame or two); leaving SENSOR_LOST needs both good for sensor_reengage_s, so that a
 * sensor that comes and goes does not toggle the mode at its own rate. */
static bool sensors_degraded(fcs_t *f, const rpas_nav_msg_t *nav, int64_t now_ns)
{
    const fcs_params_t *p = &f->prm;
    bool att = nav->flags & RPAS_NAV_AHRS, air = nav->flags & RPAS_NAV_AIR;
    f->att_seen |= att;
    f->air_seen |= air;
    bool started = age_s(now_ns, f->t0_ns) >= p->sensor_wait_s;
    if (!(att && air))
        f->sensors_ok_since_ns = -1;
    else if (f->sensors_ok_since_ns < 0)
        f->sensors_ok_since_ns = now_ns;
    if ((!att && (f->att_seen || started)) || (!air && (f->air_seen || started)))
        return true;
    return f->fallback == RPAS_FB_SENSOR_LOST && (f->sensors_ok_since_ns < 0 ||
                                                  age_s(now_ns, f->sensors_ok_since_ns) < p->sensor_reengage_s);
}

/* Picks the mode, the fallback and the targets: the mode table of docs/degraded-modes.md. */
static void select_mode(fcs_t *f, const fcs_inputs_t *in, const rpas_nav_msg_t *nav, int64_t now_ns,
                        bool *direct_ok)
{
    bool pilot_now = pilot_usable(f, in, now_ns);
    if (pilot_now) {
        f->pilot = in->pilot;
        f->pilot_seen = true;
    }
    uint32_t req = f->pilot_seen ? f->pilot.mode : RPAS_MODE_INIT;
    f->req_mode = req;

    /* Mission targets: after a stale-mission fallback they must be good for a while again. */
    bool m_ok = mission_usable(f, in, now_ns);
    if (!m_ok)
        f->mission_ok_since_ns = -1;
    else if (f->mission_ok_since_ns < 0)
        f->mission_ok_since_ns = now_ns;
    bool in_stale_fb = f->fallback == RPAS_FB_MISSION_STALE;
    bool mission_good =
        m_ok && (!in_stale_fb || age_s(now_ns, f->mission_ok_since_ns) >= f->prm.mission_reengage_s);
    f->mission_good = mission_good;

    uint32_t mode = RPAS_MODE_AUTOPILOT, fb = RPAS_FB_NONE;
    bool hold = false;
    fcs_targets_t t = f->tgt;
    *direct_ok = false;
    const rpas_pilot_msg_t *p = &f->pilot;

    switch (req) {
    case RPAS_MODE_DIRECT:
        if (stick_fresh(f, in, pilot_now, now_ns)) {
            mode = RPAS_MODE_DIRECT;
            *direct_ok = true;
        } else {
            fb = RPAS_FB_C2_LOST;
            hold = true;
        }
        break;
    case RPAS_MODE_AUTOPILOT:
        if (p->have_targets)
            t = sane_targets(f, p->lat_mode, p->vert_mode, p->hdg_deg, p->alt_ft, p->ias_kt, p->vs_fpm);
        else {
            fb = RPAS_FB_NO_TARGETS;
            hold = true;
        }
        break;
    case RPAS_MODE_MISSION:
    case RPAS_MODE_CONTINGENCY:
        if (mission_good) {
            const rpas_mission_msg_t *m = &in->mission;
            mode = m->mode;
            t = sane_targets(f, m->lat_mode, m->vert_mode, m->hdg_deg, m->alt_ft, m->ias_kt, m->vs_fpm);
            t.flags = m->flags & (RPAS_MSN_APPROACH | RPAS_MSN_FLARE | RPAS_MSN_ROLLOUT |
                                  RPAS_MSN_TERMINATE);
            if ((t.flags & (RPAS_MSN_APPROACH | RPAS_MSN_FLARE)) && isfinite(m->ias_kt))
                t.ias = nf_clamp(m->ias_kt, f->prm.ias_min_land, f->prm.ias_max);
        } else {
            fb = RPAS_FB_MISSION_STALE;
            hold = true;
        }
        break;
    default: /* nothing asked yet */
        fb = f->pilot_seen ? RPAS_FB_NO_TARGETS : RPAS_FB_C2_LOST;
        hold = true;
        break;
    }

    /* Degraded sensors: the remote pilot flies (DIRECT) while he can; without him, the state
     * is held as when the link is lost in DIRECT (below: or the attitude-free commands). */
    bool degraded = sensors_degraded(f, nav, now_ns); /* every step: it keeps its own state */
    if (degraded && req != RPAS_MODE_DIRECT) {
        if (stick_fresh(f, in, pilot_now, now_ns)) {
            mode = RPAS_MODE_DIRECT;
            fb = RPAS_FB_SENSOR_LOST;
            *direct_ok = true;
        } else {
            mode = RPAS_MODE_AUTOPILOT;
            fb = RPAS_FB_C2_LOST;
            hold = true;
        }
    }

    bool attitude = nav->flags & RPAS_NAV_AHRS;
    if (!attitude && mode != RPAS_MODE_DIRECT) {
        /* No loop can run without attitude: INIT until there has been one, else AUTOPILOT with
         * the attitude-free safe commands. Targets are captured when it returns. */
        mode = f->mode == RPAS_MODE_INIT ? RPAS_MODE_INIT : RPAS_MODE_AUTOPILOT;
        fb = RPAS_FB_NAV_INVALID;
        f->holding = false;
    } else if (mode == RPAS_MODE_DIRECT) {
        f->holding = false; /* targets stay as they were; a hold after DIRECT captures anew */
    } else if (hold) {
        if (!f->holding)
            f->tgt = capture_state(f, nav);
        f->holding = true;
    } else {
        f->tgt = t;
        f->holding = false;
    }
    f->mode = mode;
    f->fallback = fb;
}

/* Feed-forward throttle for an airspeed and a climb rate. */
static double thr_feed_forward(const fcs_params_t *p, double ias_cmd, double vs_cmd)
{
    return p->thr_ff + p->thr_ff_kt * (ias_cmd - 100.0) + p->thr_ff_vs * vs_cmd;
}

static double tas_kt(const rpas_nav_msg_t *nav)
{
    double tas = (nav->flags & RPAS_NAV_AIR) ? nf_tas_from_ias(nav->ias_kt, nav->alt_ft) : 100.0;
    return nf_clamp(tas, 40.0, 250.0);
}

static double flight_path_deg(double vs_fpm, double tas)
{
    return asin(nf_clamp(vs_fpm / (tas * NF_KT_FPM), -0.5, 0.5)) / NF_DEG;
}

/* Integrates x += k * e * dt unless the output is saturated in the direction e pushes it. */
static double integrate(double x, double k, double e, double dt, bool sat_hi, bool sat_lo, double lo,
                        double hi)
{
    double dx = k * e * dt;
    if ((dx > 0.0 && sat_hi) || (dx < 0.0 && sat_lo))
        dx = 0.0;
    return nf_clamp(x + dx, lo, hi);
}

/* Bumpless entry: loop states set so that the first commands equal the present surfaces. */
static void init_loops(fcs_t *f, const rpas_nav_msg_t *nav, const rpas_ahrs_msg_t *ahrs,
                       const double cur[4])
{
    const fcs_params_t *p = &f->prm;
    double tas = tas_kt(nav);
    f->bank_cmd = nf_clamp(nav->roll_deg, -p->bank_max, p->bank_max);
    f->hdg_i = 0.0;
    f->roll_i = nf_clamp(cur[1] - p->roll_kp * (f->bank_cmd - nav->roll_deg) + p->roll_kd * ahrs->p_dps,
                         -p->roll_i_max, p->roll_i_max);
    f->vs_cmd = nf_clamp(nav->vs_fpm, -p->vs_max, p->vs_max);
    f->vs_i = nf_clamp(nav->pitch_deg - flight_path_deg(f->vs_cmd, tas) -
                           p->vs_kp * (f->vs_cmd - nav->vs_fpm),
                       p->vs_i_min, p->vs_i_max);
    f->pitch_i = nf_clamp(-cur[0] + p->pitch_kd * ahrs->q_dps, -p->pitch_i_max, p->pitch_i_max);
    f->ias_cmd = (nav->flags & RPAS_NAV_AIR) ? nf_clamp(nav->ias_kt, p->ias_min, p->ias_max) : f->tgt.ias;
    f->thr_i = nf_clamp(cur[3] - thr_feed_forward(p, f->ias_cmd, f->vs_cmd), -p->thr_i_max, p->thr_i_max);
}

/* Envelope protection on the pitch and roll commands, in every mode: a limiting controller
 * whose output bounds the command (min/max select). nu: nose-up command. Flags when it bounds
 * the command or the attitude is beyond a limit. */
static void protect_attitude(fcs_t *f, const rpas_nav_msg_t *nav, const rpas_ahrs_msg_t *ahrs,
                             double bank_lim, double *nu, double *ail)
{
    const fcs_params_t *p = &f->prm;
    double nu_hi = p->prot_pitch_kp * (p->prot_pitch_max - nav->pitch_deg) - p->pitch_kd * ahrs->q_dps;
    double nu_lo = p->prot_pitch_kp * (p->prot_pitch_min - nav->pitch_deg) - p->pitch_kd * ahrs->q_dps;
    if (*nu > nu_hi || *nu < nu_lo || nav->pitch_deg > p->prot_pitch_max ||
        nav->pitch_deg < p->prot_pitch_min) {
        *nu = nf_clamp(*nu, nu_lo, nu_hi);
        f->env_flags |= FCS_ENV_PITCH;
    }
    double a_hi = p->prot_bank_kp * (bank_lim - nav->roll_deg) - p->roll_kd * ahrs->p_dps;
    double a_lo = p->prot_bank_kp * (-bank_lim - nav->roll_deg) - p->roll_kd * ahrs->p_dps;
    if (*ail > a_hi || *ail < a_lo || fabs(nav->roll_deg) > bank_lim) {
        *ail = nf_clamp(*ail, a_lo, a_hi);
        f->env_flags |= FCS_ENV_BANK;
    }
}

static void run_direct(fcs_t *f, const fcs_inputs_t *in, const rpas_nav_msg_t *nav, double dt,
                       bool entering, double out[4])
{
    const fcs_params_t *p = &f->prm;
    const rpas_pilot_msg_t *s = &in->pilot;
    double stick[4] = {
        -nf_clamp(finite_or(s->stk_pitch, 0.0), -1.0, 1.0), /* pull (+) is nose up: elevator - */
        nf_clamp(finite_or(s->stk_roll, 0.0), -1.0, 1.0),
        nf_clamp(finite_or(s->stk_yaw, 0.0), -1.0, 1.0),
        nf_clamp(finite_or(s->stk_thr, f->thr), 0.0, 1.0),
    };
    if (entering) {
        f->direct_blend = 0.0;
        f->blend_from[0] = f->elev;
        f->blend_from[1] = f->ail;
        f->blend_from[2] = f->rud;
        f->blend_from[3] = f->thr;
    }
    f->direct_blend = p->direct_blend_s > 0.0 ? nf_clamp(f->direct_blend + dt / p->direct_blend_s, 0.0, 1.0)
                                              : 1.0;
    for (int i = 0; i < 4; i++)
        out[i] = f->blend_from[i] + (stick[i] - f->blend_from[i]) * f->direct_blend;

    if (!(nav->flags & RPAS_NAV_AHRS))
        return;
    double nu = -out[0];
    protect_attitude(f, nav, &in->ahrs, p->prot_bank, &nu, &out[1]);
    if (nav->flags & RPAS_NAV_AIR) {
        /* speed protection: the elevator (neutral is trimmed near cruise) and the throttle */
        if (nav->ias_kt < p->prot_vmin) {
            nu = fmin(nu, -0.02 * (p->prot_vmin - nav->ias_kt));
            out[3] = 1.0;
            f->env_flags |= FCS_ENV_UNDERSPEED;
        } else if (nav->ias_kt > p->prot_vmax) {
            nu = fmax(nu, 0.02 * (nav->ias_kt - p->prot_vmax));
            out[3] = fmin(out[3], p->thr_min);
            f->env_flags |= FCS_ENV_OVERSPEED;
        }
    }
    out[0] = -nu;
}

static void run_loops(fcs_t *f, const fcs_inputs_t *in, const rpas_nav_msg_t *nav, double dt,
                      double out[4])
{
    const fcs_params_t *p = &f->prm;
    const rpas_ahrs_msg_t *ahrs = &in->ahrs;
    const fcs_targets_t *t = &f->tgt;
    bool air = nav->flags & RPAS_NAV_AIR;
    double tas = tas_kt(nav);
    double phi = nav->roll_deg, theta = nav->pitch_deg;

    /* Lateral: heading/track error -> bank command -> aileron (roll loop). */
    bool trk = t->lat_mode == RPAS_LAT_TRK && (nav->flags & (RPAS_NAV_GPS | RPAS_NAV_DR));
    double err = nf_wrap180(t->hdg - (trk ? nav->trk_deg : nav->hdg_deg));
    if (fabs(err) > 160.0 && f->bank_cmd * err < 0.0 && fabs(f->bank_cmd) > 5.0)
        err += err > 0.0 ? -360.0 : 360.0; /* keep turning the way we are near the reciprocal */
    double bank_raw = p->hdg_kp * err + f->hdg_i;
    double bank_tgt = nf_clamp(bank_raw, -p->bank_max, p->bank_max);
    if (fabs(err) < p->hdg_i_band)
        f->hdg_i = integrate(f->hdg_i, p->hdg_ki, err, dt, bank_raw >= p->bank_max,
                             bank_raw <= -p->bank_max, -p->hdg_i_max, p->hdg_i_max);
    f->bank_cmd = nf_rate_limit(f->bank_cmd, bank_tgt, p->bank_rate, dt);
    double e_phi = f->bank_cmd - phi;
    double ail_raw = p->roll_kp * e_phi - p->roll_kd * ahrs->p_dps + f->roll_i;
    double ail = nf_clamp(ail_raw, -p->ail_max, p->ail_max);
    f->roll_i = integrate(f->roll_i, p->roll_ki, e_phi, dt, ail_raw >= p->ail_max, ail_raw <= -p->ail_max,
                          -p->roll_i_max, p->roll_i_max);

    /* Yaw damper and turn coordination: yaw rate towards that of a coordinated turn; a small
     * heading term counters gust weathervaning (rudder + = yaw right). */
    double r_coord = NF_G_MPS2 * sin(phi * NF_DEG) / (tas * NF_KT_MPS) / NF_DEG;
    double rud = p->yaw_kr * (r_coord - ahrs->r_dps) + p->yaw_khdg * nf_clamp(err, -5.0, 5.0);
    rud = nf_clamp(rud, -p->rud_max, p->rud_max);

    /* Vertical: altitude error -> vertical-speed command -> pitch command -> elevator. */
    double vs_tgt = t->vert_mode == RPAS_VERT_ALT
                        ? nf_clamp(p->alt_kp * (t->alt - nav->alt_ft), -p->alt_vs_max, p->alt_vs_max)
                        : nf_clamp(t->vs, -p->vs_max, p->vs_max);
    f->vs_cmd = nf_rate_limit(f->vs_cmd, vs_tgt, p->vs_accel, dt);
    double e_vs = air ? f->vs_cmd - nav->vs_fpm : 0.0; /* no air data: feed-forward only */
    double th_raw = flight_path_deg(f->vs_cmd, tas) + p->vs_kp * e_vs + f->vs_i;
    bool spd_prot = false;
    /* on a final approach and in the flare the aircraft flies slower: a lower threshold */
    bool landing = t->flags & (RPAS_MSN_APPROACH | RPAS_MSN_FLARE);
    double vmin = landing ? p->prot_vmin_land : p->prot_vmin;
    if (air && nav->ias_kt < vmin) {
        th_raw -= p->prot_spd_pitch * (vmin - nav->ias_kt); /* nose down to regain speed */
        f->env_flags |= FCS_ENV_UNDERSPEED;
        spd_prot = true;
    } else if (air && nav->ias_kt > p->prot_vmax) {
        th_raw += p->prot_spd_pitch * (nav->ias_kt - p->prot_vmax);
        f->env_flags |= FCS_ENV_OVERSPEED;
        spd_prot = true;
    }
    double th_cmd = nf_clamp(th_raw, p->pitch_cmd_min, p->pitch_cmd_max);
    if (th_cmd != th_raw)
        f->env_flags |= FCS_ENV_PITCH;
    if (!spd_prot)
        f->vs_i = integrate(f->vs_i, p->vs_ki, e_vs, dt, th_raw >= p->pitch_cmd_max,
                            th_raw <= p->pitch_cmd_min, p->vs_i_min, p->vs_i_max);

    double e_th = th_cmd - theta;
    /* body pitch rate of a steady level turn, and the extra lift it needs */
    double cphi = fmax(cos(phi * NF_DEG), 0.5);
    double q_turn = NF_G_MPS2 * sin(phi * NF_DEG) * tan(phi * NF_DEG) / (tas * NF_KT_MPS) / NF_DEG;
    double nu_raw = p->pitch_kp * e_th - p->pitch_kd * (ahrs->q_dps - q_turn) + f->pitch_i +
                    p->turn_ff * (1.0 / cphi - 1.0);
    double nu = nf_clamp(nu_raw, -p->elev_max, p->elev_max);

    protect_attitude(f, nav, ahrs, p->prot_bank_ap, &nu, &ail);
    f->pitch_i = integrate(f->pitch_i, p->pitch_ki, e_th, dt, nu_raw > nu, nu_raw < nu, -p->pitch_i_max,
                           p->pitch_i_max);

    /* Speed: airspeed error -> throttle (PI + feed-forward); protection has priority. */
    double thr;
    if (air) {
        f->ias_cmd = nf_rate_limit(f->ias_cmd, t->ias, p->ias_rate, dt);
        double e_v = f->ias_cmd - nav->ias_kt;
        double thr_raw = thr_feed_forward(p, f->ias_cmd, f->vs_cmd) + p->thr_kp * e_v + f->thr_i;
        thr = nf_clamp(thr_raw, p->thr_min, 1.0);
        f->thr_i = integrate(f->thr_i, p->thr_ki, e_v, dt, thr_raw >= 1.0, thr_raw <= p->thr_min,
                             -p->thr_i_max, p->thr_i_max);
        if (nav->ias_kt < vmin)
            thr = 1.0;
        else if (nav->ias_kt > p->prot_vmax)
            thr = p->thr_min;
    } else {
        f->ias_cmd = t->ias;
        thr = thr_feed_forward(p, t->ias, f->vs_cmd);
    }
    /* the flare and flight termination: the engine at idle (cut), the pitch flies the path */
    if (t->flags & (RPAS_MSN_FLARE | RPAS_MSN_TERMINATE)) {
        thr = 0.0;
        f->thr_i = 0.0;
    }

    out[0] = -nu;
    out[1] = ail;
    out[2] = rud;
    out[3] = nf_clamp(thr, 0.0, 1.0);
}

/* The roll-out after a landing: engine idle, the elevator holding the nose wheel light, wings
 * level, the nose wheel (the rudder) steering the runway's course, the brakes once slow. */
static void run_rollout(fcs_t *f, const rpas_nav_msg_t *nav, double out[4])
{
    const fcs_params_t *p = &f->prm;
    double err = nf_wrap180(f->tgt.hdg - nav->hdg_deg);
    out[0] = p->rollout_elev;
    out[1] = 0.0;
    out[2] = nf_clamp(p->steer_k * err, -1.0, 1.0);
    out[3] = 0.0;
    f->brake = nav->gs_kt < p->brake_gs_kt ? p->brake_max : 0.0;
}

void fcs_step(fcs_t *f, const fcs_inputs_t *in, const rpas_nav_msg_t *nav, int64_t now_ns,
              rpas_act_cmd_msg_t *cmd, rpas_fcs_status_msg_t *status)
{
    const fcs_params_t *p = &f->prm;
    double dt = f->started ? nf_clamp(age_s(now_ns, f->last_ns), 0.0, 0.2) : 0.05;
    if (!f->started)
        f->t0_ns = now_ns;
    f->started = true;
    f->last_ns = now_ns;
    f->env_flags = 0;

    uint32_t prev_mode = f->mode;
    bool direct_ok;
    select_mode(f, in, nav, now_ns, &direct_ok);

    /* present surfaces, for bumpless entry: measured if we have them, else our last command */
    const rpas_act_status_msg_t *a = &in->act;
    bool act = in->act_ok && isfinite(a->elev) && isfinite(a->ail) && isfinite(a->rud) && isfinite(a->thr);
    double cur[4] = {act ? a->elev : f->elev, act ? a->ail : f->ail, act ? a->rud : f->rud,
                     act ? a->thr : f->thr};

    double out[4];
    f->brake = 0.0;
    if (!direct_ok && f->fallback == RPAS_FB_NONE && (f->tgt.flags & RPAS_MSN_ROLLOUT)) {
        run_rollout(f, nav, out);
        f->loops_active = false;
    } else if (direct_ok) {
        run_direct(f, in, nav, dt, prev_mode != RPAS_MODE_DIRECT, out);
        f->loops_active = false;
    } else if (f->fallback == RPAS_FB_NAV_INVALID) {
        /* attitude unknown: wings level by neutral aileron and rudder (the airframe is stable),
         * elevator at its trim estimate, throttle held */
        out[0] = f->loops_active ? -f->pitch_i : f->elev;
        out[1] = 0.0;
        out[2] = 0.0;
        /* flight termination ordered by the mission manager: the engine is cut all the same */
        bool cut = in->mission_ok && (in->mission.flags & RPAS_MSN_TERMINATE) &&
                   age_s(now_ns, in->mission.t_ns) <= p->mission_max_age_s;
        out[3] = cut ? 0.0 : f->thr;
        f->loops_active = false;
    } else {
        if (!f->loops_active)
            init_loops(f, nav, &in->ahrs, cur);
        f->loops_active = true;
        run_loops(f, in, nav, dt, out);
    }

    f->elev = nf_clamp(finite_or(out[0], 0.0), -1.0, 1.0);
    f->ail = nf_clamp(finite_or(out[1], 0.0), -1.0, 1.0);
    f->rud = nf_clamp(finite_or(out[2], 0.0), -1.0, 1.0);
    f->thr = nf_clamp(finite_or(out[3], p->thr_ff), 0.0, 1.0);

    memset(cmd, 0, sizeof *cmd);
    cmd->t_ns = now_ns;
    cmd->seq = f->seq++;
    cmd->elev = f->elev;
    cmd->ail = f->ail;
    cmd->rud = f->rud;
    cmd->thr = f->thr;
    cmd->brake = (float)f->brake;

    memset(status, 0, sizeof *status);
    status->t_ns = now_ns;
    status->mode = f->mode;
    status->req_mode = f->req_mode;
    status->fallback = f->fallback;
    status->nav_flags = nav->flags;
    status->env_flags = f->env_flags;
    status->lat_mode = f->tgt.lat_mode;
    status->vert_mode = f->tgt.vert_mode;
    status->tgt_hdg_deg = f->tgt.hdg;
    status->tgt_alt_ft = f->tgt.alt;
    status->tgt_ias_kt = f->tgt.ias;
    status->tgt_vs_fpm = f->tgt.vs;
}
