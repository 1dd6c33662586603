/* SPDX-License-Identifier: Apache-2.0 */
/* Flight-control core of nav_fcs: mode logic, fallbacks, autopilot loops, envelope protection.
 * Pure: no APEX, no I/O, no globals; one fcs_t per replica. */
#ifndef NAV_FCS_FCS_H
#define NAV_FCS_FCS_H

#include <stdbool.h>
#include <stdint.h>

#include "rpas/ports.h"

/* Gains and limits: X(name, default, meaning). Angles in degrees, rates in deg/s, speeds in
 * kt, vertical speeds in ft/min; surface commands normalised (-1..1), throttle 0..1.
 * "nu" = nose up (the elevator command is -nu). */
#define FCS_PARAMS(X)                                                                          \
    /* lateral */                                                                              \
    X(hdg_kp, 1.8, "bank per degree of heading/track error")                                  \
    X(hdg_ki, 0.03, "bank integrator, per degree-second of heading error")                    \
    X(hdg_i_max, 3.0, "heading integrator limit (bank degrees)")                              \
    X(hdg_i_band, 8.0, "heading integrator runs only within this error")                      \
    X(bank_max, 25.0, "autopilot bank command limit")                                         \
    X(bank_rate, 8.0, "bank command rate limit (deg/s)")                                      \
    X(roll_kp, 0.035, "aileron per degree of bank error")                                     \
    X(roll_ki, 0.004, "aileron integrator per degree-second of bank error")                   \
    X(roll_i_max, 0.15, "aileron integrator limit")                                           \
    X(roll_kd, 0.008, "aileron per deg/s of roll rate (damping)")                             \
    X(ail_max, 0.8, "autopilot aileron authority")                                            \
    X(yaw_kr, 0.08, "rudder per deg/s of yaw rate beyond the coordinated turn rate")          \
    X(yaw_khdg, 0.04, "rudder per degree of heading error (within +-5 deg)")                  \
    X(turn_ff, 0.15, "nu per g of extra load factor in a level turn (1/cos(bank) - 1)")       \
    X(rud_max, 0.5, "autopilot rudder authority")                                             \
    /* vertical */                                                                             \
    X(alt_kp, 12.0, "vertical-speed command per foot of altitude error (ft/min per ft)")       \
    X(alt_vs_max, 600.0, "altitude capture vertical-speed limit")                             \
    X(vs_max, 1000.0, "vertical-speed target limit in VS mode")                               \
    X(vs_accel, 250.0, "vertical-speed command rate limit (ft/min per s)")                    \
    X(vs_kp, 0.02, "pitch per ft/min of vertical-speed error")                               \
    X(vs_ki, 0.008, "pitch integrator per ft/min-second of vertical-speed error")             \
    X(vs_i_min, -6.0, "pitch integrator lower limit")                                         \
    X(vs_i_max, 10.0, "pitch integrator upper limit")                                         \
    X(pitch_cmd_min, -10.0, "autopilot pitch command lower limit")                            \
    X(pitch_cmd_max, 15.0, "autopilot pitch command upper limit")                             \
    X(pitch_kp, 0.06, "nu per degree of pitch error")                                         \
    X(pitch_ki, 0.03, "nu integrator per degree-second of pitch error")                       \
    X(pitch_i_max, 0.6, "elevator integrator limit")                                          \
    X(pitch_kd, 0.03, "nu per deg/s of pitch rate (damping)")                                 \
    X(elev_max, 0.8, "autopilot elevator authority")                                          \
    /* speed */                                                                                \
    X(ias_rate, 1.5, "airspeed command rate limit (kt/s)")                                    \
    X(ias_min, 65.0, "airspeed target lower limit")                                           \
    X(ias_max, 125.0, "airspeed target upper limit")                                          \
    X(thr_ff, 0.70, "throttle feed-forward at 100 kt level")                                  \
    X(thr_ff_kt, 0.01, "feed-forward throttle per kt above 100 kt")                           \
    X(thr_ff_vs, 0.00025, "feed-forward throttle per ft/min of commanded climb")              \
    X(thr_kp, 0.06, "throttle per kt of airspeed error")                                      \
    X(thr_ki, 0.012, "throttle integrator per kt-second")                                     \
    X(thr_i_max, 0.35, "throttle integrator limit")                                           \
    X(thr_min, 0.15, "autopilot throttle lower limit")                                        \
    /* envelope protection (all modes) */                                                      \
    X(prot_bank, 45.0, "bank protection limit")                                               \
    X(prot_bank_ap, 33.0, "bank protection limit under autopilot")                            \
    X(prot_pitch_min, -15.0, "pitch protection lower limit")                                  \
    X(prot_pitch_max, 20.0, "pitch protection upper limit")                                   \
    X(prot_vmin, 60.0, "under-speed protection threshold")                                    \
    X(prot_vmin_land, 48.0, "under-speed protection threshold on a final approach and flare") \
    X(ias_min_land, 55.0, "airspeed target lower limit on a final approach and flare")        \
    X(prot_vmax, 135.0, "over-speed protection threshold")                                    \
    X(prot_spd_pitch, 1.0, "pitch change per kt beyond a speed threshold")                    \
    X(prot_bank_kp, 0.03, "protection aileron per degree beyond the bank limit")              \
    X(prot_pitch_kp, 0.1, "protection nu per degree beyond a pitch limit")                   \
    /* timing */                                                                               \
    X(pilot_max_age_s, 1.5, "a pilot message older than this is stale")                       \
    X(stick_max_age_s, 1.0, "stick data older than this: DIRECT is not available")            \
    X(mission_max_age_s, 1.0, "mission targets older than this are stale")                    \
    X(mission_reengage_s, 1.0, "mission targets must be good this long to leave a fallback")  \
    X(direct_blend_s, 1.0, "fade from the last autopilot command to the stick on DIRECT")     \
    X(sensor_wait_s, 1.0, "after the start, attitude or air data never seen counts as lost")   \
    X(sensor_reengage_s, 2.0, "attitude and air data good this long to leave SENSOR_LOST")    \
    /* roll-out after a landing */                                                             \
    X(steer_k, 0.08, "rudder (nose-wheel steering) per degree of course error on the ground") \
    X(rollout_elev, -0.1, "elevator on the ground (nose-up: keeps weight off the nose wheel)") \
    X(brake_gs_kt, 55.0, "brakes only below this ground speed")                               \
    X(brake_max, 0.5, "wheel brake command on the roll-out")

typedef struct {
#define FCS_PARAM_FIELD(name, def, doc) double name;
    FCS_PARAMS(FCS_PARAM_FIELD)
#undef FCS_PARAM_FIELD
} fcs_params_t;

/* The latest message of each input port; *_ok as in nav_inputs_t. */
typedef struct {
    rpas_pilot_msg_t pilot;
    rpas_mission_msg_t mission;
    rpas_act_status_msg_t act;
    rpas_ahrs_msg_t ahrs; /* body rates (p, q, r); used when nav has RPAS_NAV_AHRS */
    bool pilot_ok, mission_ok, act_ok;
} fcs_inputs_t;

/* env_flags bits (FCS_STATUS_OUT) */
#define FCS_ENV_BANK 0x1
#define FCS_ENV_PITCH 0x2
#define FCS_ENV_OVERSPEED 0x4
#define FCS_ENV_UNDERSPEED 0x8

typedef struct {
    double hdg, alt, ias, vs;
    uint32_t lat_mode, vert_mode;
    uint32_t flags; /* the mission's RPAS_MSN_* (landing phases, termination); 0 otherwise */
} fcs_targets_t;

typedef struct {
    fcs_params_t prm;
    bool started;
    int64_t last_ns;
    uint32_t seq;
    /* mode logic */
    uint32_t mode, req_mode, fallback;
    bool pilot_seen;
    rpas_pilot_msg_t pilot;  /* the last good pilot message */
    bool holding;            /* targets are a captured state (a fallback or NO_TARGETS) */
    fcs_targets_t tgt;       /* the targets being flown */
    bool mission_good;       /* mission targets accepted (after mission_reengage_s) */
    int64_t mission_ok_since_ns;
    int64_t t0_ns;           /* the first step */
    bool att_seen, air_seen; /* the navigation has had attitude / air data once */
    int64_t sensors_ok_since_ns; /* attitude and air data both good since (-1: not now) */
    /* control state */
    bool loops_active;       /* autopilot loops running (else re-initialised on entry) */
    double bank_cmd, vs_cmd, ias_cmd;
    double hdg_i, roll_i, vs_i, pitch_i, thr_i;
    double direct_blend;     /* 0..1: share of the stick in DIRECT */
    double blend_from[4];    /* elev, ail, rud, thr when DIRECT was entered */
    double elev, ail, rud, thr, brake; /* last commands */
    uint32_t env_flags;
} fcs_t;

void fcs_default_params(fcs_params_t *prm);
/* prm may be NULL for the defaults. */
void fcs_init(fcs_t *fcs, const fcs_params_t *prm);
/* One control cycle at now_ns from the navigation solution; writes the actuator command and
 * the status (both stamped now_ns). */
void fcs_step(fcs_t *fcs, const fcs_inputs_t *in, const rpas_nav_msg_t *nav, int64_t now_ns,
              rpas_act_cmd_msg_t *cmd, rpas_fcs_status_msg_t *status);

#endif /* NAV_FCS_FCS_H */
