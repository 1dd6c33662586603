/* SPDX-License-Identifier: Apache-2.0 */
/* Navigation core of nav_fcs: the navigation solution (NAV_OUT) from GPS, AHRS and air data,
 * with validity monitoring and dead reckoning on GPS loss. Pure: no APEX, no I/O, no globals. */
#ifndef NAV_FCS_NAV_H
#define NAV_FCS_NAV_H

#include <stdbool.h>
#include <stdint.h>

#include "rpas/ports.h"

/* The latest message of each sensor port; *_ok: READ_SAMPLING_MESSAGE returned NO_ERROR, the
 * right length and VALID (the core adds its own freshness and sequence checks). */
typedef struct {
    rpas_gps_msg_t gps;
    rpas_ahrs_msg_t ahrs;
    rpas_air_msg_t air;
    bool gps_ok, ahrs_ok, air_ok;
} nav_inputs_t;

typedef struct {
    double gps_max_age_s;  /* a GPS message older than this is stale */
    double gps_frozen_s;   /* GPS_CNT unchanged this long: receiver frozen */
    double ahrs_max_age_s;
    double ahrs_frozen_s;
    double ahrs_stuck_s;   /* every AHRS value unchanged this long, counter running: stuck */
    double air_max_age_s;
    double air_frozen_s;
    double wind_tau_s;     /* time constant of the wind estimate's low-pass filter */
    double wind_max_roll_deg; /* no wind update above this bank (sideslip, heading errors) */
} nav_params_t;

/* Freshness of a sequence counter: when it last changed. */
typedef struct {
    bool seen;
    uint32_t seq;
    int64_t t_change_ns;
} nav_seq_t;

typedef struct {
    nav_params_t prm;
    bool started;
    int64_t last_ns;
    nav_seq_t gps_seq, ahrs_seq, air_seq;
    double ahrs_vals[9];     /* the AHRS values of the last sample that changed one of them */
    bool ahrs_vals_seen;
    int64_t ahrs_vals_change_ns;
    bool have_pos;       /* lat/lon known (from a GPS fix, then dead reckoning) */
    double lat_deg, lon_deg;
    double vn_kt, ve_kt; /* ground velocity used to propagate the position */
    bool wind_ok;
    double wind_n_kt, wind_e_kt;
    int64_t wind_t_ns;   /* time of the last wind update */
    rpas_nav_msg_t out;  /* the last solution (held values when a source is lost) */
} nav_t;

void nav_default_params(nav_params_t *prm);
/* prm may be NULL for the defaults. */
void nav_init(nav_t *nav, const nav_params_t *prm);
/* One navigation cycle at time now_ns; writes the solution to *out (also kept in nav->out). */
void nav_update(nav_t *nav, const nav_inputs_t *in, int64_t now_ns, rpas_nav_msg_t *out);

#endif /* NAV_FCS_NAV_H */
