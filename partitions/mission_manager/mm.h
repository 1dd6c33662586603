/* SPDX-License-Identifier: Apache-2.0 */
/* The mission manager's core, in three layers ("3T"): the mission layer (mm.c: the plan, the
 * operational mode, contingencies as preemptions of the current leg), the sequencing layer
 * (mm_legs.c: each leg as lateral and vertical manoeuvres, its termination) and the guidance
 * layer (mm_guidance.c: the targets nav_fcs flies). Geometry in a local frame (mm_geo.c).
 * Pure: no APEX, no I/O, no globals; each function takes its state by pointer, so the unit
 * tests and several replicas run it in one process. Same inputs, same outputs, bit for bit. */
#ifndef MM_H
#define MM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rpas/mission_plan.h"
#include "rpas/ports.h"

/* Gains and limits: X(name, default, meaning). */
#define MM_PARAMS(X)                                                                           \
    X(chi_inf_deg, 60.0, "largest angle at which a path is approached (far from it)")          \
    X(xte_scale_m, 250.0, "cross-track error at which the approach angle is half chi_inf")     \
    X(arc_lead_s, 2.5, "course lead on arcs: the turn rate times this")                        \
    X(turn_bank_deg, 20.0, "bank of the fly-by turns, Dubins paths and made-up orbits")       \
    X(wind_hdg_ratio, 0.8, "wind over true airspeed above which the track is not commanded")  \
    X(alt_kp, 10.0, "vertical speed per foot of altitude error (ft/min per ft)")              \
    X(alt_band_ft, 50.0, "altitude reached: within this")                                     \
    X(energy_kb, 40.0, "vertical speed given up per kt of airspeed deficit (ft/min per kt)")  \
    X(energy_dead_kt, 3.0, "airspeed error the energy balance lets pass")                     \
    X(c2_max_age_s, 0.25, "the pilot's last frame older than this: the C2 link is lost")    \
    X(cmd_max_age_s, 1.0, "io's plan-agreement message older than this is not used")         \
    X(traffic_max_age_s, 2.0, "a traffic report older than this is not used")                 \
    X(hold_default_leg_s, 60.0, "leg time of a plan's hold that gives none")                  \
    X(hold_rate_dps, 3.0, "turn rate of holds (standard rate), unless max_bank_deg is less")  \
    X(gear_ft, 4.4, "height of the altitude reference above the main wheels on the ground")   \
    X(radalt_max_age_s, 0.3, "a radar altitude older than this is not used")                  \
    X(approach_ias_kt, 70.0, "final approach airspeed of an AUTOLAND that gives none")        \
    X(flare_ias_kt, 55.0, "airspeed target in the flare (the throttle is at idle)")          \
    X(flare_ft, 15.0, "wheel height at which the flare begins")                              \
    X(flare_tau_min_s, 2.0, "the flare's time constant, at least (taken from the sink then)") \
    X(flare_sink_fps, 2.0, "the sink rate the flare aims for at the ground")                 \
    X(flare_xte_k, 0.5, "flare: course correction per metre off the centre line")            \
    X(runway_xte_k, 1.0, "roll-out: course correction per metre off the centre line")

typedef struct {
#define MM_PARAM_FIELD(name, value, meaning) double name;
    MM_PARAMS(MM_PARAM_FIELD)
#undef MM_PARAM_FIELD
} mm_params_t;

void mm_params_default(mm_params_t *p);

/* ---- geometry (mm_geo.c) ---------------------------------------------------------------- */

typedef struct {
    double n, e; /* metres north and east of the plan's origin */
} mm_vec_t;

typedef struct {
    double lat0_deg, lon0_deg, coslat0;
} mm_frame_t;

void mm_frame_init(mm_frame_t *f, double lat0_deg, double lon0_deg);
mm_vec_t mm_to_local(const mm_frame_t *f, double lat_deg, double lon_deg);
mm_vec_t mm_from_e7(const mm_frame_t *f, int32_t lat_e7, int32_t lon_e7);
mm_vec_t mm_vec(double course_deg, double len_m); /* a vector along a course */
double mm_course(mm_vec_t from, mm_vec_t to);      /* 0..360 */
double mm_dist(mm_vec_t a, mm_vec_t b);
mm_vec_t mm_add(mm_vec_t a, mm_vec_t b);
mm_vec_t mm_sub(mm_vec_t a, mm_vec_t b);
mm_vec_t mm_scale(mm_vec_t a, double k);

/* A path segment the guidance follows. */
enum mm_seg_kind { MM_SEG_LINE = 0, MM_SEG_ARC = 1, MM_SEG_HDG = 2, MM_SEG_TURN = 3 };
typedef struct {
    int kind;      /* enum mm_seg_kind */
    mm_vec_t a, b; /* LINE: from a to b */
    mm_vec_t c;    /* ARC: centre */
    double r;      /* ARC: radius */
    int dir;       /* ARC, TURN: +1 right (clockwise seen from above), -1 left */
    double crs;    /* LINE: course a->b; HDG: the heading; TURN: the course to turn to */
} mm_seg_t;

/* Where the aircraft is against a segment. */
typedef struct {
    double path_crs; /* course of the path at the closest point */
    double xte_m;    /* cross-track error, + right of the path */
    double along_m;  /* LINE: distance along from a */
    double to_go_m;  /* LINE: distance along to b */
} mm_track_t;

mm_seg_t mm_line(mm_vec_t a, mm_vec_t b);
mm_seg_t mm_arc(mm_vec_t centre, double r, int dir);
mm_track_t mm_track(const mm_seg_t *s, mm_vec_t p);

/* Hold entries (ARINC 424 / ICAO Doc 8168: sectors by the heading at the fix against the
 * inbound course, boundary 70 degrees off the inbound course on the holding side). */
enum mm_hold_entry { MM_ENTRY_DIRECT = 0, MM_ENTRY_PARALLEL = 1, MM_ENTRY_TEARDROP = 2 };
int mm_hold_entry(double heading_deg, double inbound_deg, int dir);

/* Turn radius at a bank for a ground speed. */
double mm_turn_radius(double gs_mps, double bank_deg);
/* A hold's turn radius: a turn at rate_dps, or at max_bank_deg if that is less. */
double mm_hold_radius(double tas_mps, double rate_dps, double max_bank_deg);

/* The shortest CSC Dubins path from pose (p0, crs0) to (p1, crs1) with turn radius r: the
 * first arc, the straight and the last arc. False when none exists (the poses too close). */
typedef struct {
    mm_seg_t arc1, line, arc2;
    mm_vec_t t1, t2; /* the tangent points */
    double length_m;
} mm_dubins_t;
bool mm_dubins(mm_vec_t p0, double crs0, mm_vec_t p1, double crs1, double r, mm_dubins_t *out);

/* ---- inputs and outputs ------------------------------------------------------------------ */

typedef struct {
    bool nav_ok, fcs_ok, cmd_ok, traffic_ok, radalt_ok;
    rpas_nav_msg_t nav;
    rpas_fcs_status_msg_t fcs;
    rpas_pilot_msg_t pilot; /* the last one, valid or not: its time is the link's last sign */
    rpas_mm_cmd_msg_t cmd;
    rpas_traffic_msg_t traffic;
    rpas_radalt_msg_t radalt;
    /* a plan image that arrived this cycle (NULL: none) and its CRC as the uplink gave it */
    const void *plan;
    size_t plan_len;
    uint32_t plan_crc;
} mm_inputs_t;

/* ---- the sequencing layer's state (mm_legs.c) --------------------------------------------- */

typedef struct {
    int leg;         /* index in the plan; -1: none */
    int phase;       /* leg-specific */
    mm_seg_t seg;    /* the segment flown now */
    mm_vec_t start;  /* position when the leg began */
    double start_alt_ft;
    double path_len_m; /* LINE legs: the geometric length (for a geometric vertical path) */
    double turned_deg; /* accumulated turn (orbits, holds) */
    double last_bearing;
    int laps;
    int pass;
    int entry;       /* holds: enum mm_hold_entry */
    bool racetrack;  /* holds: the entry is flown */
    double arc_rem0; /* Dubins: the first arc's angle when it began */
    double flare_tau; /* AUTOLAND: the flare's time constant, from the sink rate it began with */
    /* fly-by: the course of the leg before, when it ended early to turn onto this one (NaN:
     * not so); the turn is flown as an arc tangent to both, then the leg's own segment */
    double flyby_crs;
    bool turning_in;
    mm_seg_t main;
    mm_vec_t rt_c1, rt_c2, rt_o0, rt_o1, rt_i0; /* holds: the racetrack */
    int64_t phase_t0_ns;
    mm_dubins_t dubins;
    bool done;
    const char *note; /* set for one cycle when the leg reaches a milestone (for the report) */
} mm_leg_state_t;

/* One leg with its positions in the local frame. */
typedef struct {
    rpas_plan_leg_t raw;
    mm_vec_t fix, p2;
    mm_vec_t from;  /* the fix of the leg before that has one */
    bool has_from;
    double next_crs; /* the course the path leaves the fix on (NaN: not known: no fly-by) */
} mm_leg_t;

typedef struct {
    rpas_plan_header_t hdr;
    mm_leg_t leg[RPAS_PLAN_MAX_LEGS];
    mm_frame_t frame;
    uint32_t crc;
    bool loaded;
} mm_plan_t;

/* Checks and decodes a plan image. 0, or -1 with a reason in err. */
int mm_plan_load(mm_plan_t *plan, const void *image, size_t len, uint32_t crc, char *err,
                 size_t errlen);

/* What the guidance needs of the present state. */
typedef struct {
    mm_vec_t pos;
    double alt_ft, ias_kt, gs_mps, trk_deg, vs_fpm;
    double tas_mps, wind_mps;
    double wheels_agl_ft; /* the radar altimeter's height (NaN: none: from the altitude) */
    int64_t t_ns;
} mm_state_t;

/* The guidance's demand for one cycle. */
typedef struct {
    double crs_deg;     /* course (or heading when hdg) */
    bool hdg;           /* fly a heading, not a track */
    double alt_ft;      /* the altitude reference */
    double vs_ff_fpm;   /* a geometric path's own vertical speed (0: none) */
    double ias_kt;
    double xte_m, to_go_m;
    bool raw_vs;        /* the vertical speed as demanded (the flare): no energy balance */
    double centre_k;    /* > 0: the course corrects this many deg per metre off the line
                           (the flare, the runway), within 10 deg; 0: the vector field */
} mm_demand_t;

/* Starts leg L (from the present state; alt_ref_ft: the altitude flown so far). */
void mm_leg_start(mm_leg_state_t *ls, const mm_leg_t *L, const rpas_plan_header_t *hdr,
                  const mm_params_t *prm, const mm_state_t *st, double alt_ref_ft);
/* One cycle of leg L: its demand; ls->done once the leg's terminator is met. */
void mm_leg_step(mm_leg_state_t *ls, const mm_leg_t *L, const mm_params_t *prm,
                 const mm_state_t *st, mm_demand_t *d);

/* ---- the guidance layer (mm_guidance.c) --------------------------------------------------- */

/* The desired course on a segment (vector field: the approach angle falls from chi_inf far
 * from the path to 0 on it; arcs add their turn rate as a lead). */
double mm_lateral(const mm_params_t *prm, const mm_seg_t *s, const mm_track_t *tk, double gs_mps);
/* The targets for nav_fcs from a demand, within the plan's envelope. */
void mm_guidance(const mm_params_t *prm, const rpas_plan_header_t *hdr, const mm_state_t *st,
                 const mm_demand_t *d, uint32_t mode, rpas_mission_msg_t *out);

/* ---- the mission layer (mm.c) ------------------------------------------------------------ */

typedef struct {
    mm_params_t prm;
    mm_plan_t plan;    /* the plan flown */
    mm_plan_t pending; /* a plan received, waiting for the replicas' agreement */
    bool have_pending;
    uint32_t state;    /* enum rpas_mm_state */
    uint32_t ct_active; /* the contingency in force (RPAS_CT_*), or RPAS_CT_COUNT */
    uint32_t ct_flags;  /* bit k: contingency k's condition holds (declared) */
    int64_t cond_since[RPAS_CT_COUNT]; /* when each condition began to hold (-1: not) */
    int64_t ct_t0_ns;   /* when the contingency in force was declared */
    int64_t prev_ns;    /* the previous cycle's time (0: none yet) */
    int resume_leg;     /* the mission leg to resume at */
    bool proc_started;
    bool engaged;       /* the flight control has flown MISSION since the plan was activated */
    uint32_t last_cmd_seq;
    bool have_cmd_seq;
    mm_leg_state_t ls;
    mm_leg_t synth;     /* a leg made up in flight (direct-to, hold here, avoid), when ls flies it */
    bool flying_synth;
    double alt_ref_ft;
    mm_demand_t last;
    char event[96];     /* the last state change, for the partition's report ("" none) */
    uint32_t rejected;  /* plans refused */
} mm_t;

void mm_init(mm_t *mm, const mm_params_t *prm);
/* One cycle at now_ns: the targets (false: none to send) and the status. */
bool mm_step(mm_t *mm, const mm_inputs_t *in, int64_t now_ns, rpas_mission_msg_t *target,
             rpas_mm_status_msg_t *status);

const char *mm_state_name(uint32_t s);
const char *mm_leg_name(int type);
const char *mm_ct_name(uint32_t c);

#endif
