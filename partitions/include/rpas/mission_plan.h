/* SPDX-License-Identifier: Apache-2.0 */
/* The mission plan as it is uplinked and as the mission manager holds it: a binary image,
 * little-endian, fixed-size records, no pointers. `ima mission` compiles a plan
 * (config/missions/NAME.yaml) into this image (python/ima/mission/image.py mirrors this file; a
 * test checks the two agree), the remote pilot station sends it over the C2 link on CAN
 * (docs/mission.md, "Uplink"), io reassembles it and checks its CRC, and the mission manager
 * checks it again before it flies it.
 *
 * An image is one rpas_plan_header_t followed by n_legs rpas_plan_leg_t. Legs 0 ..
 * n_mission_legs-1 are the mission; the legs after them are the contingency procedures', each
 * procedure a range of them (rpas_plan_contingency_t). Positions are WGS-84 latitude and
 * longitude in 1e-7 degrees (about 1 cm); courses and headings are true, in degrees;
 * altitudes in feet above mean sea level; airspeeds in knots (indicated). A float that does
 * not apply to a leg is NaN ("no constraint"). */
#ifndef RPAS_MISSION_PLAN_H
#define RPAS_MISSION_PLAN_H

#include <stddef.h>
#include <stdint.h>

#include "crc32.h" /* rpas_crc32: the uplink's check */

#define RPAS_PLAN_MAGIC 0x4E4C504Du /* "MPLN" as little-endian bytes */
#define RPAS_PLAN_VERSION 1
#define RPAS_PLAN_MAX_LEGS 48

/* The path terminators of ARINC 424 the mission manager flies, and the extended legs. */
enum rpas_leg_type {
    RPAS_LEG_IF = 1,       /* initial fix: where the path starts (not flown: the next leg's origin) */
    RPAS_LEG_TF = 2,       /* track to a fix: the great-circle (here: straight) path from the previous fix */
    RPAS_LEG_DF = 3,       /* direct to a fix: from where the aircraft is when the leg starts */
    RPAS_LEG_CF = 4,       /* course to a fix: the inbound `course_deg` ending at the fix */
    RPAS_LEG_RF = 5,       /* constant-radius arc to the fix about centre (lat2, lon2) */
    RPAS_LEG_CA = 6,       /* course to an altitude: track `course_deg` until `alt_ft` */
    RPAS_LEG_FA = 7,       /* fix to an altitude: from the fix along `course_deg` until `alt_ft` */
    RPAS_LEG_VA = 8,       /* heading to an altitude: heading `course_deg` until `alt_ft` */
    RPAS_LEG_HA = 9,       /* hold at the fix until `alt_ft` is reached */
    RPAS_LEG_HF = 10,      /* hold at the fix: one circuit, then on */
    RPAS_LEG_HM = 11,      /* hold at the fix: `count` circuits (0: until the pilot moves on) */
    RPAS_LEG_DUBINS = 12,  /* the shortest Dubins path to the fix, arriving on `course_deg` */
    RPAS_LEG_SCAN = 13,    /* lawnmower over an area: `count` passes from the fix */
    RPAS_LEG_ORBIT = 14,   /* circle about the fix, radius `a` m, for `b` s (0: laps) or `count` laps */
    RPAS_LEG_DIRECT = 15,  /* direct-to as the pilot commands it (as DF, from where it is then) */
    RPAS_LEG_AUTOLAND = 16 /* GPS autoland on the runway whose threshold is the fix */
};

/* rpas_plan_leg_t.flags */
#define RPAS_LEG_FLY_OVER 0x01   /* the fix is flown over before turning (else fly-by) */
#define RPAS_LEG_TURN_RIGHT 0x02 /* RF, holds, orbits: right turns; SCAN: passes step right */
#define RPAS_LEG_TURN_LEFT 0x04  /* left turns; SCAN: passes step left (neither flag: right) */
#define RPAS_LEG_ALT_PATH 0x08   /* reach alt_ft at the fix on a geometric path (else climb or
                                    descend at once at constant airspeed, then level off) */

/* One leg: 48 bytes. What `course_deg` and `a`..`d` mean depends on the type:
 *
 * | type | course_deg | a | b | c | d | lat2/lon2 |
 * |---|---|---|---|---|---|---|
 * | CF, CA, FA | the course flown | | | | | |
 * | VA | the heading flown | | | | | |
 * | HA, HF, HM | inbound course | leg time (s) | | | | |
 * | DUBINS | course at the fix | turn radius (m) | | | | |
 * | SCAN | direction of the first pass | pass length (m) | spacing (m) | | | |
 * | ORBIT | | radius (m) | time (s; 0: `count` laps) | | | |
 * | RF | | | | | | centre |
 * | AUTOLAND | runway heading | glide path (deg) | aim point from the threshold (m) | runway length (m) | runway width (m) | |
 *
 * AUTOLAND's alt_ft is the threshold's elevation (ft MSL) and its ias_kt the approach speed
 * (NaN: 70 kt). A leg without a fix (CA, VA) carries latitude and longitude 0. */
typedef struct {
    uint8_t type;   /* enum rpas_leg_type */
    uint8_t flags;  /* RPAS_LEG_* */
    uint16_t count; /* HM, ORBIT: laps; SCAN: passes */
    int32_t lat_e7, lon_e7;
    int32_t lat2_e7, lon2_e7;
    float course_deg;
    float alt_ft; /* altitude constraint at the leg's end (NaN: none, keep the last) */
    float ias_kt; /* airspeed for the leg (NaN: the plan's cruise) */
    float a, b, c, d;
} rpas_plan_leg_t;

/* The contingency events, in the order of rpas_plan_header_t.contingency[]. */
enum rpas_contingency {
    RPAS_CT_C2_LOSS = 0,     /* the pilot's uplink is lost */
    RPAS_CT_GPS_LOSS = 1,    /* the navigation solution has no GPS */
    RPAS_CT_TRAFFIC = 2,     /* an intruder inside the separation the plan declares */
    RPAS_CT_AP_DISENGAGE = 3,/* the flight control no longer follows the autopilot */
    RPAS_CT_TERMINATION = 4, /* C2 loss, then the autopilot disengaged: flight termination */
    RPAS_CT_COUNT = 5
};

/* What a contingency does once detected. */
enum rpas_ct_action {
    RPAS_CTA_NONE = 0,      /* not declared: ignored */
    RPAS_CTA_PROCEDURE = 1, /* continue `continue_s`, then fly the procedure's legs */
    RPAS_CTA_AVOID = 2,     /* traffic: turn away by p1 (the plan's offset_deg) and climb or
                               descend p2 (altitude_offset_ft) away from the intruder until clear */
    RPAS_CTA_HOLD = 3,      /* hold where it is (an orbit about the present position) */
    RPAS_CTA_TERMINATE = 4  /* flight termination: the engine cut (nav_fcs), state latched */
};

/* One contingency: 24 bytes. */
typedef struct {
    uint8_t action; /* enum rpas_ct_action */
    uint8_t resume; /* 1: back to the mission when the event clears (at the leg it left) */
    uint16_t first_leg, n_legs; /* the procedure: legs [first_leg, first_leg + n_legs) */
    uint16_t pad;
    float detect_s;   /* how long the condition must hold before it is declared */
    float continue_s; /* how long the mission goes on before the procedure starts */
    float p1, p2;     /* AVOID: the turn away (deg) and the climb or descent away (ft) */
} rpas_plan_contingency_t;

/* The header: 200 bytes. */
typedef struct {
    uint32_t magic;   /* RPAS_PLAN_MAGIC */
    uint16_t version; /* RPAS_PLAN_VERSION */
    uint16_t n_legs;  /* legs that follow, 1..RPAS_PLAN_MAX_LEGS */
    uint16_t n_mission_legs;
    uint16_t flags;   /* reserved, 0 */
    uint32_t plan_id; /* the plan's own number (the station shows it) */
    int32_t origin_lat_e7, origin_lon_e7; /* the local frame's origin */
    float cruise_ias_kt, cruise_alt_ft;
    float min_ias_kt, max_ias_kt; /* envelope: no airspeed target outside */
    float max_bank_deg;           /* the steepest bank: holds, and the planned arcs' radii */
    float max_vs_fpm;             /* climb and descent rates */
    float traffic_h_m, traffic_v_ft; /* loss of separation with an intruder: closer than both */
    float pad[6];
    rpas_plan_contingency_t contingency[RPAS_CT_COUNT];
} rpas_plan_header_t;

#define RPAS_PLAN_MAX_BYTES (sizeof(rpas_plan_header_t) + RPAS_PLAN_MAX_LEGS * sizeof(rpas_plan_leg_t))

_Static_assert(sizeof(rpas_plan_leg_t) == 48, "a leg is 48 bytes");
_Static_assert(sizeof(rpas_plan_contingency_t) == 24, "a contingency is 24 bytes");
_Static_assert(sizeof(rpas_plan_header_t) == 200, "the header is 200 bytes");

#endif
