/* SPDX-License-Identifier: Apache-2.0 */
/* Navigation core: source monitoring, GPS/dead-reckoning position, wind estimate. */
#include "nav.h"

#include <math.h>
#include <string.h>

#include "nf_math.h"

void nav_default_params(nav_params_t *prm)
{
    prm->gps_max_age_s = 1.0;
    prm->gps_frozen_s = 0.7; /* 5 Hz receiver: three missed fixes */
    prm->ahrs_max_age_s = 0.2;
    prm->ahrs_frozen_s = 0.2;
    prm->ahrs_stuck_s = 0.5; /* 25 samples at 50 Hz: noise alone never repeats them all */
    prm->air_max_age_s = 0.4;
    prm->air_frozen_s = 0.4;
    prm->wind_tau_s = 20.0;
    prm->wind_max_roll_deg = 10.0;
}

void nav_init(nav_t *nav, const nav_params_t *prm)
{
    memset(nav, 0, sizeof *nav);
    if (prm)
        nav->prm = *prm;
    else
        nav_default_params(&nav->prm);
}

/* True while the counter keeps changing (a first sighting counts as a change). */
static bool seq_alive(nav_seq_t *s, uint32_t seq, int64_t now_ns, double frozen_s)
{
    if (!s->seen || seq != s->seq) {
        s->seen = true;
        s->seq = seq;
        s->t_change_ns = now_ns;
        return true;
    }
    return (double)(now_ns - s->t_change_ns) * 1e-9 < frozen_s;
}

static bool fresh(int64_t now_ns, int64_t t_ns, double max_age_s)
{
    return (double)(now_ns - t_ns) * 1e-9 <= max_age_s;
}

static bool all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return false;
    return true;
}

static bool gps_usable(nav_t *nav, const nav_inputs_t *in, int64_t now_ns)
{
    const rpas_gps_msg_t *g = &in->gps;
    if (!in->gps_ok)
        return false;
    /* the counter is tracked even for a message we reject, so a frozen one stays frozen */
    bool alive = seq_alive(&nav->gps_seq, g->seq, now_ns, nav->prm.gps_frozen_s);
    double v[] = {g->lat_deg, g->lon_deg, g->alt_ft, g->gs_kt, g->trk_deg};
    return alive && fresh(now_ns, g->t_ns, nav->prm.gps_max_age_s) && g->fix >= 2 &&
           all_finite(v, 5) && fabs(g->lat_deg) <= 89.0 && fabs(g->lon_deg) <= 180.0 &&
           g->gs_kt >= 0.0 && g->gs_kt < 1000.0;
}

/* True while the values keep changing. A real AHRS's outputs carry noise: attitude, rates and
 * accelerations all repeating bit for bit, sample after sample, is a sensor stuck behind a
 * live counter and a valid status, which the counter check cannot see. */
static bool values_alive(nav_t *nav, const double v[9], int64_t now_ns)
{
    bool same = nav->ahrs_vals_seen;
    for (int i = 0; i < 9 && same; i++)
        same = v[i] == nav->ahrs_vals[i];
    if (!same) {
        memcpy(nav->ahrs_vals, v, sizeof nav->ahrs_vals);
        nav->ahrs_vals_seen = true;
        nav->ahrs_vals_change_ns = now_ns;
        return true;
    }
    return (double)(now_ns - nav->ahrs_vals_change_ns) * 1e-9 < nav->prm.ahrs_stuck_s;
}

static bool ahrs_usable(nav_t *nav, const nav_inputs_t *in, int64_t now_ns)
{
    const rpas_ahrs_msg_t *a = &in->ahrs;
    if (!in->ahrs_ok)
        return false;
    bool alive = seq_alive(&nav->ahrs_seq, a->seq, now_ns, nav->prm.ahrs_frozen_s);
    double v[] = {a->roll_deg, a->pitch_deg, a->hdg_deg, a->p_dps, a->q_dps, a->r_dps,
                  a->ax_g, a->ay_g, a->az_g};
    bool moving = values_alive(nav, v, now_ns);
    return alive && moving && fresh(now_ns, a->t_ns, nav->prm.ahrs_max_age_s) &&
           (a->status & 0x3) == 0x3 && all_finite(v, 9) && fabs(a->roll_deg) <= 180.0 &&
           fabs(a->pitch_deg) <= 90.0;
}

static bool air_usable(nav_t *nav, const nav_inputs_t *in, int64_t now_ns)
{
    const rpas_air_msg_t *d = &in->air;
    if (!in->air_ok)
        return false;
    bool alive = seq_alive(&nav->air_seq, d->seq, now_ns, nav->prm.air_frozen_s);
    double v[] = {d->ias_kt, d->alt_ft, d->vs_fpm};
    return alive && fresh(now_ns, d->t_ns, nav->prm.air_max_age_s) && (d->status & 0x1) &&
           all_finite(v, 3) && d->ias_kt >= 0.0 && d->ias_kt < 400.0;
}

/* Moves the position by a ground velocity for dt seconds (flat Earth over one step). */
static void propagate(nav_t *nav, double vn_kt, double ve_kt, double dt)
{
    double dn = vn_kt * NF_KT_MPS * dt, de = ve_kt * NF_KT_MPS * dt;
    nav->lat_deg += dn / NF_EARTH_R_M / NF_DEG;
    nav->lon_deg += de / (NF_EARTH_R_M * cos(nav->lat_deg * NF_DEG)) / NF_DEG;
    nav->lon_deg = nf_wrap180(nav->lon_deg);
    nav->lat_deg = nf_clamp(nav->lat_deg, -89.0, 89.0);
}

void nav_update(nav_t *nav, const nav_inputs_t *in, int64_t now_ns, rpas_nav_msg_t *out)
{
    double dt = nav->started ? (double)(now_ns - nav->last_ns) * 1e-9 : 0.0;
    dt = nf_clamp(dt, 0.0, 0.5);
    nav->started = true;
    nav->last_ns = now_ns;

    uint32_t gps_new_seq = nav->gps_seq.seq;
    bool gps_seen_before = nav->gps_seq.seen;
    bool gps = gps_usable(nav, in, now_ns);
    bool gps_new = gps && (!gps_seen_before || in->gps.seq != gps_new_seq);
    bool ahrs = ahrs_usable(nav, in, now_ns);
    bool air = air_usable(nav, in, now_ns);

    rpas_nav_msg_t *o = &nav->out;
    o->t_ns = now_ns;
    o->flags = 0;

    if (ahrs) {
        o->flags |= RPAS_NAV_AHRS;
        o->roll_deg = in->ahrs.roll_deg;
        o->pitch_deg = in->ahrs.pitch_deg;
        o->hdg_deg = nf_wrap360(in->ahrs.hdg_deg);
    }
    if (air) {
        o->flags |= RPAS_NAV_AIR;
        o->ias_kt = in->air.ias_kt;
        o->alt_ft = in->air.alt_ft;
        o->vs_fpm = in->air.vs_fpm;
    } else if (gps && in->gps.fix >= 3) {
        o->alt_ft = in->gps.alt_ft; /* geometric altitude: better than a held one */
    }

    /* Air-relative velocity (north, east) from TAS and heading, for wind and dead reckoning. */
    double tas = air ? nf_tas_from_ias(in->air.ias_kt, in->air.alt_ft) : 0.0;
    double van = tas * cos(o->hdg_deg * NF_DEG), vae = tas * sin(o->hdg_deg * NF_DEG);

    if (gps) {
        o->flags |= RPAS_NAV_GPS;
        double trk = in->gps.trk_deg * NF_DEG;
        nav->vn_kt = in->gps.gs_kt * cos(trk);
        nav->ve_kt = in->gps.gs_kt * sin(trk);
        if (gps_new) {
            /* the fix, carried forward to now with its own velocity */
            nav->lat_deg = in->gps.lat_deg;
            nav->lon_deg = in->gps.lon_deg;
            double age = nf_clamp((double)(now_ns - in->gps.t_ns) * 1e-9, 0.0, 1.0);
            propagate(nav, nav->vn_kt, nav->ve_kt, age);
            nav->have_pos = true;
            /* wind = ground velocity - air velocity, only in near wings-level flight */
            if (ahrs && air && fabs(o->roll_deg) <= nav->prm.wind_max_roll_deg) {
                double wn = nav->vn_kt - van, we = nav->ve_kt - vae;
                if (!nav->wind_ok) {
                    nav->wind_n_kt = wn;
                    nav->wind_e_kt = we;
                    nav->wind_ok = true;
                } else {
                    double h = nf_clamp((double)(now_ns - nav->wind_t_ns) * 1e-9, 0.0, 5.0);
                    double a = h / (nav->prm.wind_tau_s + h);
                    nav->wind_n_kt += a * (wn - nav->wind_n_kt);
                    nav->wind_e_kt += a * (we - nav->wind_e_kt);
                }
                nav->wind_t_ns = now_ns;
            }
        } else if (nav->have_pos) {
            propagate(nav, nav->vn_kt, nav->ve_kt, dt);
        }
    } else if (nav->have_pos && ahrs && air) {
        /* dead reckoning: air velocity plus the last wind estimate */
        o->flags |= RPAS_NAV_DR;
        nav->vn_kt = van + (nav->wind_ok ? nav->wind_n_kt : 0.0);
        nav->ve_kt = vae + (nav->wind_ok ? nav->wind_e_kt : 0.0);
        propagate(nav, nav->vn_kt, nav->ve_kt, dt);
    }

    if (o->flags & (RPAS_NAV_GPS | RPAS_NAV_DR)) {
        o->lat_deg = nav->lat_deg;
        o->lon_deg = nav->lon_deg;
        o->gs_kt = hypot(nav->vn_kt, nav->ve_kt);
        o->trk_deg = nf_wrap360(atan2(nav->ve_kt, nav->vn_kt) / NF_DEG);
    }
    o->wind_n_kt = nav->wind_ok ? nav->wind_n_kt : 0.0;
    o->wind_e_kt = nav->wind_ok ? nav->wind_e_kt : 0.0;
    *out = *o;
}
