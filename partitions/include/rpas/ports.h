/* SPDX-License-Identifier: Apache-2.0 */
/* The RPAS application's intra-node port messages: what the io partition, nav_fcs and the
 * mission manager exchange through sampling ports. Engineering units, doubles, each
 * message stamped with the emulated time its data was taken (the end of the CAN frame it came
 * from, or the time the producing partition computed it). Port names, sizes and the struct each
 * port carries are in the system model (config/applications/rpas.yaml), from which the build
 * generates the partitions' contract. A message that stops coming makes its port INVALID after
 * the port's refresh period: that is how a consumer sees a lost sensor, link or partition. */
#ifndef RPAS_PORTS_H
#define RPAS_PORTS_H

#include <stdint.h>

/* Flight-control modes, as in FCS_STATUS.FCS_MODE and PILOT_MODE.PIL_MODE (config/can/rpas.dbc). */
enum rpas_mode {
    RPAS_MODE_INIT = 0,
    RPAS_MODE_DIRECT = 1,
    RPAS_MODE_AUTOPILOT = 2,
    RPAS_MODE_MISSION = 3,
    RPAS_MODE_CONTINGENCY = 4,
};
enum rpas_lat_mode { RPAS_LAT_HDG = 0, RPAS_LAT_TRK = 1 };
enum rpas_vert_mode { RPAS_VERT_ALT = 0, RPAS_VERT_VS = 1 };
/* Why the FCS is not in the mode the pilot asked for (FCS_STATUS.FCS_FALLBACK). */
enum rpas_fallback {
    RPAS_FB_NONE = 0,
    RPAS_FB_C2_LOST = 1,       /* pilot link lost: AUTOPILOT holding the current state */
    RPAS_FB_MISSION_STALE = 2, /* MISSION/CONTINGENCY targets stale: AUTOPILOT holding */
    RPAS_FB_NAV_INVALID = 3,   /* no usable navigation solution */
    RPAS_FB_NO_TARGETS = 4,    /* AUTOPILOT asked before any target arrived: holding */
    RPAS_FB_SENSOR_LOST = 5,   /* attitude (AHRS) or air data unusable: autopilot disengaged,
                                  DIRECT for the remote pilot (C2 up) */
};

/* io -> nav_fcs: port GPS_IN (5 Hz) */
typedef struct {
    int64_t t_ns;
    uint32_t seq; /* GPS_CNT: a frozen receiver repeats it */
    uint32_t fix; /* 0 no fix, 2 2D, 3 3D */
    uint32_t sats;
    uint32_t pad;
    double lat_deg, lon_deg, alt_ft, gs_kt, trk_deg;
} rpas_gps_msg_t;

/* io -> nav_fcs: port AHRS_IN (50 Hz; the three AHRS frames of one sample) */
typedef struct {
    int64_t t_ns;
    uint32_t seq;
    uint32_t status; /* bit0 valid, bit1 aligned */
    double roll_deg, pitch_deg, hdg_deg; /* heading: true, 0..360 */
    double p_dps, q_dps, r_dps;          /* body rates */
    double ax_g, ay_g, az_g;             /* body specific force */
} rpas_ahrs_msg_t;

/* io -> nav_fcs: port AIR_IN (20 Hz) */
typedef struct {
    int64_t t_ns;
    uint32_t seq;
    uint32_t status; /* bit0 valid */
    double ias_kt, alt_ft, vs_fpm; /* baro altitude */
} rpas_air_msg_t;

/* io -> nav_fcs: port PILOT_IN (C2 uplink; written only while uplink frames arrive) */
typedef struct {
    int64_t t_ns;
    uint32_t mode;      /* enum rpas_mode the pilot asks for (0: none yet) */
    uint32_t lat_mode;  /* enum rpas_lat_mode */
    uint32_t vert_mode; /* enum rpas_vert_mode */
    uint32_t have_targets; /* a PILOT_TARGETS frame has arrived */
    double hdg_deg, alt_ft, ias_kt, vs_fpm;            /* autopilot targets */
    double stk_pitch, stk_roll, stk_yaw, stk_thr;      /* -1..1 (thr 0..1); pitch + = pull */
    int64_t t_stick_ns; /* time of the last PILOT_STICK frame (0: none) */
} rpas_pilot_msg_t;

/* io -> nav_fcs: port ACT_IN (smart actuators' measured positions) */
typedef struct {
    int64_t t_ns;
    uint32_t state; /* 0 normal, 1 holding last command, 2 safe position */
    uint32_t pad;
    double elev, ail, rud, thr;
} rpas_act_status_msg_t;

/* nav_fcs -> io: port ACT_CMD_OUT (normalised; elevator + = nose down) */
typedef struct {
    int64_t t_ns;
    uint32_t seq;
    float brake; /* wheel brakes 0..1 (the roll-out after a landing; 0 in flight) */
    double elev, ail, rud, thr;
} rpas_act_cmd_msg_t;

/* nav_fcs -> io: port FCS_STATUS_OUT */
typedef struct {
    int64_t t_ns;
    uint32_t mode, req_mode, fallback; /* enum rpas_mode, rpas_mode, rpas_fallback */
    uint32_t nav_flags;                /* bit0 GPS, bit1 AHRS, bit2 air data valid, bit3 DR */
    uint32_t env_flags;                /* bit0 bank, bit1 pitch limited, bit2 over-, bit3 underspeed */
    uint32_t lat_mode, vert_mode;
    uint32_t pad;
    double tgt_hdg_deg, tgt_alt_ft, tgt_ias_kt, tgt_vs_fpm;
} rpas_fcs_status_msg_t;

/* nav_fcs -> io, the recorder and the mission manager: port NAV_OUT, the navigation solution */
#define RPAS_NAV_GPS 0x1
#define RPAS_NAV_AHRS 0x2
#define RPAS_NAV_AIR 0x4
#define RPAS_NAV_DR 0x8
typedef struct {
    int64_t t_ns;
    uint32_t flags; /* RPAS_NAV_* */
    uint32_t pad;
    double lat_deg, lon_deg, alt_ft;
    double ias_kt, gs_kt, trk_deg, hdg_deg, vs_fpm;
    double roll_deg, pitch_deg;
    double wind_n_kt, wind_e_kt; /* wind estimate: where the air moves to */
} rpas_nav_msg_t;

/* The mission manager's state (rpas_mm_status_msg_t.state, MISSION_STATUS_x.MS_STATE_x). */
enum rpas_mm_state {
    RPAS_MM_NO_PLAN = 0,     /* no plan yet: no targets */
    RPAS_MM_STANDBY = 1,     /* a plan, the flight control not in MISSION yet: targets, no sequencing */
    RPAS_MM_ACTIVE = 2,      /* flying the plan's legs */
    RPAS_MM_PAUSED = 3,      /* the pilot paused: holding where it was */
    RPAS_MM_CONTINGENCY = 4, /* a contingency's procedure preempts the plan */
    RPAS_MM_COMPLETE = 5,    /* the last leg is done: orbiting where it ended (or stopped, landed) */
    RPAS_MM_TERMINATED = 6,  /* flight termination: the defined safe state */
};

/* The pilot's mission commands (MISSION_CMD.MC_CMD). */
enum rpas_mm_cmd {
    RPAS_MMC_NONE = 0,
    RPAS_MMC_ENGAGE = 1,    /* fly the plan from its first leg */
    RPAS_MMC_PAUSE = 2,     /* hold where it is */
    RPAS_MMC_RESUME = 3,    /* back to the leg it paused on */
    RPAS_MMC_DIRECT_TO = 4, /* direct to leg `leg`'s fix, then on from there */
};

/* io -> mission manager: port MM_CMD_IN (each major frame) */
typedef struct {
    int64_t t_ns;
    uint32_t plan_crc; /* the plan every member node holds (agreed over DDS; 0: none agreed) */
    uint32_t cmd_seq;  /* the pilot's command counter: a new value is a new command */
    uint32_t cmd;      /* enum rpas_mm_cmd */
    uint32_t leg;      /* DIRECT_TO: the leg */
} rpas_mm_cmd_msg_t;

/* io -> mission manager: port RADALT_IN (the radar altimeter, below its range) */
typedef struct {
    int64_t t_ns;
    uint32_t seq;
    uint32_t valid;   /* 1: a height */
    double height_ft; /* of the main wheels above the ground */
} rpas_radalt_msg_t;

/* io -> mission manager: port TRAFFIC_IN (the surveillance receiver's nearest intruder,
 * relative to the aircraft) */
typedef struct {
    int64_t t_ns;
    uint32_t seq;
    uint32_t valid; /* 1: an intruder is reported */
    double dn_m, de_m; /* where it is: north and east of the aircraft */
    double dalt_ft;    /* its altitude minus the aircraft's */
    double trk_deg;    /* its track */
    double pad;
} rpas_traffic_msg_t;

/* mission manager -> io (downlink MISSION_STATUS_x): port MM_STATUS_OUT */
typedef struct {
    int64_t t_ns;
    uint32_t state;       /* enum rpas_mm_state */
    uint32_t contingency; /* the contingency in force (enum rpas_contingency), 255 none */
    uint32_t ct_flags;    /* bit k: contingency k's condition is declared */
    uint32_t plan_id, plan_crc;
    int32_t leg;          /* the active leg, -1 none */
    uint32_t leg_type;    /* enum rpas_leg_type */
    uint32_t phase;
    double to_go_m;       /* distance to go on the leg */
    double xte_m;         /* cross-track error, + right of the path */
    double alt_ref_ft;    /* the vertical path's altitude now */
} rpas_mm_status_msg_t;

/* rpas_mission_msg_t.flags: the phases of an automatic landing and flight termination, in
 * which nav_fcs flies outside its usual envelope. */
#define RPAS_MSN_APPROACH 0x1  /* final approach: airspeed targets down to the approach speed */
#define RPAS_MSN_FLARE 0x2     /* flare: throttle to idle, the vertical speed flown by pitch */
#define RPAS_MSN_ROLLOUT 0x4   /* on the runway: idle, wheel brakes, steer the centre line */
#define RPAS_MSN_TERMINATE 0x8 /* flight termination: engine cut, wings level */

/* mission manager -> nav_fcs: port MISSION_IN (targets for MISSION / CONTINGENCY) */
typedef struct {
    int64_t t_ns;
    uint32_t mode; /* RPAS_MODE_MISSION or RPAS_MODE_CONTINGENCY */
    uint32_t lat_mode, vert_mode;
    uint32_t flags; /* RPAS_MSN_* */
    double hdg_deg; /* heading or track, by lat_mode */
    double alt_ft, ias_kt, vs_fpm;
} rpas_mission_msg_t;

#endif
