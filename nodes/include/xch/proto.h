/* SPDX-License-Identifier: Apache-2.0 */
/* The cross-channel link between a node's io partition and its DDS agent (ima-dds-node).
 *
 * Partitions cannot host Cyclone DDS (it starts threads; the partitions' seccomp filter forbids
 * them), so each node runs one agent process beside its SKE: the node's DDS participant. The
 * io partition (the system partition, the only one with Linux I/O) talks to it over one
 * Unix-domain SOCK_SEQPACKET connection, at the path of io's --dds argument (the node's module
 * gives it: `{dds_socket}` in the system model, ddsK.sock in the run's socket directory; the
 * agent listens there with --socket). Every datagram starts with struct xch_hdr; its size is
 * exactly sizeof(hdr) + the payload size of its type.
 *
 * io -> agent
 *   HELLO      once after connecting; hdr.node = this node (1..XCH_MAX_NODES).
 *   INPUTS     once per major frame (io's rx process, at the frame start), payload
 *              struct xch_inputs: the sensor samples this node holds. hdr.frame = major frame
 *              number (t / 50 ms), hdr.t_ns = the frame start. The agent publishes it on
 *              topic "rpas_CrossChannelInputs" and answers with one AGREED for that frame.
 *   HEALTH     when it changes and at least once a second (io_health_due), payload struct
 *              xch_health -> topic "rpas_NodeHealth"
 *              (deadline and liveliness QoS: how the other nodes see this one on DDS).
 *   TELEMETRY  once per major frame (io's tx process), struct xch_telemetry -> "rpas_Telemetry".
 *   MISSION    when the mission/pilot targets change, struct xch_mission -> "rpas_MissionData".
 *
 * agent -> io
 *   WELCOME    answer to HELLO (no payload); hdr.node = the agent's node, hdr.frame = number
 *              of nodes in the system. The agent accepts io only once it has discovered every
 *              other node's agent (or they are known dead), so the first exchange is complete.
 *   AGREED     payload struct xch_agreed: the INPUTS for hdr.frame of this node and of each
 *              node of the request's wait mask that published them (present says which).
 *              Emulated time: the agent waits until every node in the request's wait mask
 *              that is alive on DDS (liveliness) has published that frame; a node that is
 *              dead on DDS, or whose io link is down, is not waited for. So the content
 *              depends only on which nodes published the frame, never on timing (the rules,
 *              and the one exception of a node whose io link just came back, are in
 *              nodes/dds/agent__agree.h). Real time: it waits at most the agent's
 *              --xch-timeout-us (default 2000) after the request, then answers with what it
 *              has.
 *
 * Membership is not decided here: io derives it deterministically from the nodes' heartbeats
 * on CAN (FCS_STATUS_x) and passes it in HEALTH and as the wait mask. */
#ifndef XCH_PROTO_H
#define XCH_PROTO_H

#include <stdint.h>

#define XCH_MAGIC 0x48435849u /* "IXCH" as little-endian bytes */
#define XCH_VERSION 1
#define XCH_MAX_NODES 3

enum xch_type {
    XCH_HELLO = 1,
    XCH_WELCOME = 2,
    XCH_INPUTS = 3,
    XCH_AGREED = 4,
    XCH_HEALTH = 5,
    XCH_TELEMETRY = 6,
    XCH_MISSION = 7,
};

struct xch_hdr {
    uint32_t magic;   /* XCH_MAGIC */
    uint16_t version; /* XCH_VERSION */
    uint16_t type;    /* enum xch_type */
    uint32_t node;    /* sender's node, 1..XCH_MAX_NODES (agent: its node) */
    uint32_t frame;   /* major frame number */
    int64_t t_ns;     /* emulated time of the frame start (or of the data) */
};

/* struct xch_inputs.valid */
#define XCH_IN_GPS 0x1
#define XCH_IN_AHRS 0x2
#define XCH_IN_AIR 0x4

/* One node's sensor samples for a frame (the newest of each it holds). */
struct xch_inputs {
    uint32_t valid;     /* XCH_IN_*: which samples are held */
    uint32_t wait_mask; /* io -> agent: nodes to wait for (bit k-1 = node k); ignored otherwise */
    int64_t gps_t_ns, ahrs_t_ns, air_t_ns;
    uint32_t gps_seq, gps_fix, gps_sats;
    uint32_t ahrs_seq, ahrs_status;
    uint32_t air_seq, air_status;
    uint32_t plan_crc; /* the CRC-32 of the mission plan this node holds (0: none): a plan is
                          activated once every member holds the same (partitions/io/uplink.c) */
    double gps[5];  /* lat_deg, lon_deg, alt_ft, gs_kt, trk_deg */
    double ahrs[9]; /* roll, pitch, hdg (deg); p, q, r (deg/s); ax, ay, az (g) */
    double air[3];  /* ias_kt, alt_ft, vs_fpm */
};

struct xch_agreed {
    uint32_t present; /* bit k-1: node k's INPUTS for the frame are in in[k-1] */
    uint32_t pad;
    struct xch_inputs in[XCH_MAX_NODES];
};

/* struct xch_health.flags */
#define XCH_HEALTH_DISAGREE 0x1 /* this node's own output is voted out by its self-monitor */
#define XCH_HEALTH_NAV_VALID 0x2

struct xch_health {
    uint32_t membership; /* bit k-1: node k is a member (io's CAN-heartbeat view) */
    uint32_t flags;      /* XCH_HEALTH_* */
    uint32_t fcs_mode;   /* enum rpas_mode */
    uint32_t failed;     /* bit k-1: node k's replica voted out by this node's self-monitor */
    uint64_t hm_events;  /* reserved, 0 */
};

struct xch_telemetry {
    uint32_t fcs_mode, fallback, nav_flags, pad;
    double lat_deg, lon_deg, alt_ft, ias_kt, gs_kt, hdg_deg, trk_deg, vs_fpm, roll_deg, pitch_deg;
    double cmd[4]; /* this replica's actuator command: elev, ail, rud, thr */
};

struct xch_mission {
    uint32_t mode, lat_mode, vert_mode, pad;
    double hdg_deg, alt_ft, ias_kt, vs_fpm;
};

_Static_assert(sizeof(struct xch_hdr) == 24, "header is 24 bytes");
_Static_assert(sizeof(struct xch_inputs) == 200, "inputs are 200 bytes");

#endif
