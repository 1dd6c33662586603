/* SPDX-License-Identifier: Apache-2.0 */
/* A kinematic aircraft that flies nav_fcs's targets as the mission manager gives them, and the
 * inputs the mission manager would read of it: the closed loop of the core's unit tests and
 * of its benchmark. */
#ifndef MM_KINEMATIC_H
#define MM_KINEMATIC_H

#include <math.h>
#include <string.h>

#include "mm.h"
#include "nf_math.h"

#define LAT0 47.0
#define LON0 8.0

typedef struct {
    double n, e, alt, trk, ias;
    int64_t t;
    double wind_n, wind_e; /* kt */
} ac_t;

static inline void ac_init(ac_t *a)
{
    *a = (ac_t){.alt = 3000.0, .trk = 90.0, .ias = 100.0};
}

/* 50 ms of flight towards the targets: the track turns at up to 5 deg/s (1 per deg of error),
 * the vertical speed is followed at once, the airspeed at 2 kt/s. */
static inline void ac_step(ac_t *a, const rpas_mission_msg_t *m)
{
    double dt = 0.05;
    double err = nf_wrap180(m->hdg_deg - a->trk);
    double rate = nf_clamp(1.0 * err, -5.0, 5.0);
    a->trk = nf_wrap360(a->trk + rate * dt);
    a->alt += nf_clamp(m->vs_fpm, -1000.0, 1000.0) / 60.0 * dt;
    a->ias = nf_rate_limit(a->ias, m->ias_kt, 2.0, dt);
    double v = a->ias * NF_KT_MPS;
    a->n += (v * cos(a->trk * NF_DEG) + a->wind_n * NF_KT_MPS) * dt;
    a->e += (v * sin(a->trk * NF_DEG) + a->wind_e * NF_KT_MPS) * dt;
    a->t += 50000000;
}

typedef struct {
    bool c2_up, gps_ok, fcs_mission, traffic;
    uint32_t agreed_crc;
    uint32_t cmd_seq, cmd, cmd_leg;
    uint32_t fcs_mode;
    int64_t pilot_t; /* the pilot's last frame: the link's last sign of life */
} world_t;

static inline void inputs(const ac_t *a, world_t *w, mm_inputs_t *in)
{
    memset(in, 0, sizeof *in);
    rpas_nav_msg_t *n = &in->nav;
    in->nav_ok = true;
    n->t_ns = a->t;
    n->flags = RPAS_NAV_AHRS | RPAS_NAV_AIR | (w->gps_ok ? RPAS_NAV_GPS : RPAS_NAV_DR);
    n->lat_deg = LAT0 + a->n / (NF_DEG * NF_EARTH_R_M);
    n->lon_deg = LON0 + a->e / (NF_DEG * NF_EARTH_R_M * cos(LAT0 * NF_DEG));
    n->alt_ft = a->alt;
    n->ias_kt = a->ias;
    n->gs_kt = a->ias;
    n->trk_deg = a->trk;
    n->hdg_deg = a->trk;
    in->fcs_ok = true;
    in->fcs.mode = w->fcs_mode ? w->fcs_mode : (w->fcs_mission ? RPAS_MODE_MISSION : RPAS_MODE_AUTOPILOT);
    if (w->c2_up)
        w->pilot_t = a->t;
    in->pilot.t_ns = w->pilot_t; /* the port keeps the last message when it goes invalid */
    in->cmd_ok = true;
    in->cmd = (rpas_mm_cmd_msg_t){.t_ns = a->t, .plan_crc = w->agreed_crc, .cmd_seq = w->cmd_seq,
                                  .cmd = w->cmd, .leg = w->cmd_leg};
    in->traffic_ok = true;
    in->traffic = (rpas_traffic_msg_t){.t_ns = a->t, .valid = w->traffic, .dn_m = 300.0,
                                       .de_m = 200.0, .dalt_ft = -100.0};
}

#endif
