/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition's core, free of APEX and of I/O: its settings (from its arguments), CAN
 * receive (frames -> port messages), CAN transmit (port messages -> frames on this node's
 * redundancy channel) and redundancy (membership, self-monitoring, input agreement). Each
 * function works on the state it is given; main.c owns the one instance and does the I/O. */
#ifndef IO_CORE_H
#define IO_CORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "canbus/proto.h"
#include "fi/wrong_output.h"
#include "rpas/ports.h"
#include "voter/voter.h"
#include "xch/proto.h"

#define IO_AXES 4           /* elev, ail, rud, thr */
#define IO_PATH_MAX 108     /* a Unix socket path */
/* A node name, so that "<node>/io" is a bus client name (CANBUS_NAME_LEN with its NUL). */
#define IO_NAME_MAX (CANBUS_NAME_LEN - 3)
#define IO_MAX_FAULTS 4     /* --fault arguments */

/* ---- settings (settings.c) ------------------------------------------------------------- */

/* What reaches io from its node's module (`ima:Linux Arguments`, filled in by `ima deploy`). */
typedef struct {
    char node[IO_NAME_MAX];   /* --node: the node's name; io joins the bus as "<node>/io" */
    unsigned channel;         /* --node-index minus 1: the redundancy channel A=0..C=2 */
    uint32_t node_mask;       /* --nodes=1,2,3: the system's nodes by index (bit k: index k+1) */
    unsigned n_nodes;         /* channels 0 .. the highest node's (1..3) */
    char canbus[IO_PATH_MAX]; /* --canbus: the CAN bus socket */
    char dds[IO_PATH_MAX];    /* --dds: the DDS agent socket (used with more than one node) */
    double vote_threshold[IO_AXES]; /* --vote-thresholds=elev,ail,rud,thr */
    unsigned vote_persist;          /* --vote-persist */
    unsigned membership_misses;     /* --membership-missed-frames */
    /* --fault=wrong_output:... (fi/wrong_output.h), repeatable: faults this replica injects
     * into its own command; --test-cmd-bias=AXIS=OFFSET@SECONDS is one of them, a permanent
     * bias (fid test-cmd-bias) */
    fi_wo_t fault[IO_MAX_FAULTS];
    unsigned n_faults;
} io_settings_t;

/* Parses argv[1..argc-1]. Every setting but the faults is required. 0, or -1 with one line in
 * err naming the argument at fault. */
int io_settings_parse(io_settings_t *s, int argc, char *const argv[], char *err, size_t errlen);
const char *io_axis_name(int axis); /* "elev", "ail", "rud", "thr" */
/* The command's axes with their ranges (the DBC's), as the faults name them. */
extern const fi_wo_axis_t io_axes[IO_AXES];

/* ---- the mission plan's uplink (uplink.c) ------------------------------------------------ */

#include "rpas/mission_plan.h"

enum io_uplink_event {
    IO_UPLINK_NONE = 0,
    IO_UPLINK_STARTED,    /* an upload announced */
    IO_UPLINK_COMPLETE,   /* a plan came whole and its CRC holds: plan_new */
    IO_UPLINK_BAD_CRC,    /* a plan came whole and its CRC fails: dropped */
    IO_UPLINK_BAD_HEADER, /* an announcement with an impossible length */
};

typedef struct {
    bool receiving;
    unsigned cnt;        /* the upload being received (MUP_CNT) */
    uint32_t len, crc;   /* as announced */
    unsigned got;        /* segments received */
    uint8_t have[(RPAS_PLAN_MAX_BYTES + 6 * 8 - 1) / (6 * 8)];
    uint8_t buf[RPAS_PLAN_MAX_BYTES];
    /* the last plan received whole with a good CRC */
    uint8_t plan[RPAS_PLAN_MAX_BYTES];
    uint32_t plan_len, plan_crc;
    bool plan_new; /* to be sent to the mission manager */
    uint64_t refused; /* uploads refused (a bad announcement, a CRC that fails) */
} io_uplink_t;

void io_uplink_init(io_uplink_t *u);
/* One MISSION_UPLOAD frame's segment: enum io_uplink_event. */
int io_uplink_segment(io_uplink_t *u, unsigned seg, unsigned cnt, uint64_t data);
/* The plan every member holds, from the agreed inputs of a frame (previous: the agreement so
 * far, kept while a member is not heard or the members differ). */
uint32_t io_plan_agreement(const struct xch_agreed *ag, uint32_t members, uint32_t previous);

/* ---- CAN receive (can_rx.c) -------------------------------------------------------------- */

/* The samples decoded from the frames of a major frame; `*_new`: to be written to the port. */
typedef struct {
    rpas_gps_msg_t gps;
    rpas_ahrs_msg_t ahrs;
    rpas_air_msg_t air;
    rpas_pilot_msg_t pilot;
    rpas_act_status_msg_t act;
    rpas_mm_cmd_msg_t mm_cmd;   /* the pilot's last mission command (plan_crc: io fills in) */
    rpas_traffic_msg_t traffic;
    rpas_radalt_msg_t radalt;
    io_uplink_t uplink;
    int uplink_event;           /* enum io_uplink_event of the frame, the last that is not NONE */
    bool gps_pos; /* GPS_POS came: GPS_VEL completes the sample */
    bool gps_new, ahrs_new, air_new, pilot_new, act_new, traffic_new, radalt_new;
    /* the time stamps of the samples last written to the ports (-1: none yet) */
    int64_t last_gps_t, last_ahrs_t, last_air_t;
    uint64_t decode_errors, unknown_frames;
} io_rx_t;

/* What the frames say of the other replicas (read by the redundancy functions). */
typedef struct {
    uint32_t hb_seen; /* bit k: node k's heartbeat came since the last membership update */
    struct {
        bool have;
        double v[IO_AXES];
    } cmd[XCH_MAX_NODES]; /* each replica's command as it went on CAN */
} io_peers_t;

void io_rx_init(io_rx_t *rx);
/* One frame the bus delivered. Frames not ours are counted, never trusted. */
void io_rx_frame(io_rx_t *rx, io_peers_t *peers, unsigned n_nodes, const struct canbus_rec *r);
/* The samples have been written to their ports: clears the *_new flags, notes the times. */
void io_rx_written(io_rx_t *rx);

/* ---- CAN transmit (can_tx.c) ------------------------------------------------------------- */

#define IO_TX_MAX_FRAMES 6
#define IO_NAV_EVERY 2 /* NAV_POS / NAV_DATA every other major frame (10 Hz) */

typedef struct {
    uint32_t id;
    uint8_t len;
    uint8_t data[8];
} io_frame_t;

/* nav_fcs's outputs of a frame, as read from io's destination ports. */
typedef struct {
    bool have_cmd, have_status, have_nav, have_mm;
    rpas_act_cmd_msg_t cmd;
    rpas_fcs_status_msg_t status;
    rpas_nav_msg_t nav;
    rpas_mm_status_msg_t mm; /* the mission manager's status */
} io_outputs_t;

/* ---- faults (faults.c) ------------------------------------------------------------------- */

/* Where each of io's faults is in its spells. */
typedef struct {
    fi_wo_state_t wo[IO_MAX_FAULTS];
} io_fault_state_t;

/* The lines to report (REPORT_APPLICATION_MESSAGE), in order. */
typedef struct {
    unsigned n;
    char line[2 * IO_MAX_FAULTS][FI_WO_REPORT_MAX];
} io_fault_reports_t;

void io_faults_init(io_fault_state_t *st);
/* io's faults at t (the time of its transmission): the command as they make it (cmd NULL when
 * there is none this frame) and the reports due ("fault <fid> wrong_output applied ..."). */
void io_cmd_faults(const io_settings_t *s, io_fault_state_t *st, int64_t t_ns,
                   rpas_act_cmd_msg_t *cmd, io_fault_reports_t *out);

/* ---- CAN transmit, continued ----------------------------------------------------------- */
/* The frames of major frame `frame` on redundancy channel `channel`: ACT_CMD_x, FCS_STATUS_x,
 * BRAKE_CMD_x while nav_fcs brakes, and every IO_NAV_EVERY frames NAV_POS_x, NAV_DATA_x and
 * MISSION_STATUS_x. Values are clamped to the DBC's
 * ranges (NaN to the neutral value in range). `sent_cmd` gets the command as the others
 * decode it (when have_cmd). Returns the number of frames in out. */
int io_tx_frames(const io_outputs_t *o, unsigned channel, uint32_t frame,
                 io_frame_t out[IO_TX_MAX_FRAMES], double sent_cmd[IO_AXES]);
/* The replica's telemetry for DDS. */
void io_telemetry(const io_outputs_t *o, struct xch_telemetry *tm);

/* ---- redundancy (membership.c, agreement.c) ---------------------------------------------- */

typedef struct {
    unsigned n_nodes, channel, misses;
    uint32_t members; /* bit k: node k is a member (latched out once lost) */
    unsigned hb_missed[XCH_MAX_NODES];
    io_peers_t peers;
    struct {
        bool have;
        double v[IO_AXES];
    } own_cmd; /* this replica's last command as it went on CAN */
    voter_t selfmon;
    bool selfmon_on, own_voted_out;
    uint32_t peers_voted_out;
    voter_t in_vote[3]; /* GPS, AHRS, air data over the members' copies */
    /* A member's sample stamped after the end of the frame, or older than its port's refresh
     * period, is left out of the agreement (0: no bound). */
    int64_t frame_ns, max_age_ns[3];
    uint64_t refused_stamps[XCH_MAX_NODES];
    uint32_t refused_new; /* nodes with a sample refused since the caller last looked */
    uint32_t plan_agreed; /* the plan every member holds (0: none yet) */
    struct xch_mission last_mission;
    uint32_t last_mission_frame;
    bool mission_sent;
    struct xch_health last_health; /* the health last given to the DDS agent */
    uint32_t last_health_frame;
    bool health_sent; /* false: the next health goes out whatever it says (a new agent) */
} io_red_t;

/* A node's health goes to DDS when it changes, and at least every this many frames (1 s):
 * the other nodes watch the node through its inputs, every frame, and its health together
 * (nodes/dds/agent_dds.c, handle_deadline). */
#define IO_HEALTH_REFRESH_FRAMES 20

/* 0, or -1 if the voters refuse the settings. */
int io_red_init(io_red_t *red, const io_settings_t *s);
/* The heartbeats of the frame that ended: returns the nodes lost now (bits). */
uint32_t io_membership_update(io_red_t *red);

typedef struct {
    uint32_t newly_failed; /* bit k: node k's command voted out now */
    bool own_out;          /* ... and it is this node's own */
    bool disagree;         /* two replicas left and they disagree */
    const char *reason[XCH_MAX_NODES]; /* "miscompare" / "absent" of the newly failed */
} io_monitor_t;

/* Votes the replicas' commands of the frame that ended as the actuators do. */
void io_self_monitor(io_red_t *red, io_monitor_t *out);
/* This node's samples for the exchange. */
void io_inputs(const io_rx_t *rx, struct xch_inputs *in);
/* Replaces rx's samples by the agreed ones (newer than what the ports hold) of the frame
 * starting at `now`; see frame_ns and max_age_ns for the samples left out. */
void io_apply_agreed(io_red_t *red, io_rx_t *rx, const struct xch_agreed *ag, int64_t now);
/* This node's health for DDS. */
void io_health(const io_red_t *red, uint32_t fcs_mode, struct xch_health *h);
/* True if health h is due for DDS at `frame`: it differs from the last one given, or that
 * one is IO_HEALTH_REFRESH_FRAMES old, or none was given since health_sent was cleared. */
bool io_health_due(io_red_t *red, const struct xch_health *h, uint32_t frame);
/* Mission data for DDS when the pilot's targets change, and once a second: true if due. */
bool io_mission_due(io_red_t *red, const rpas_pilot_msg_t *pilot, uint32_t frame,
                    struct xch_mission *out);
/* "node1,node3" for a node mask. */
void io_node_list(uint32_t mask, unsigned n_nodes, char *buf, size_t len);

#endif
