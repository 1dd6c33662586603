/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition (system partition, the only one with Linux I/O): bridges the avionics CAN
 * bus, the node's DDS agent and the node's sampling ports. Process `rx` (every major frame, at
 * its start) decodes the frames the bus delivered; process `tx` (every major frame,
 * IO_TX_OFFSET later, after nav_fcs has run) encodes nav_fcs's outputs onto CAN with this
 * node's redundancy channel.
 *
 * In a redundant system (IMA_NODES > 1) rx also:
 *   - keeps the node membership: node k is a member while its heartbeat (FCS_STATUS on its
 *     redundancy channel) keeps coming; IMA_MEMBERSHIP_MISSES frames without one remove it
 *     (latched). Every node sees the same broadcast bus at the same instants, so every node
 *     computes the same membership: it is agreed without a protocol of its own.
 *   - exchanges its sensor inputs with the other nodes over DDS (the agent at $IMA_XCH) and
 *     feeds nav_fcs the agreed inputs: for each sensor, the newest sample any member holds,
 *     its values voted (ima voter: median of 3, average of 2) over the members that hold it.
 *     So healthy replicas compute from the same data.
 *   - monitors its own last actuator command against the other replicas' (the same voter and
 *     thresholds as the actuators): when its own channel is voted out it raises an
 *     APPLICATION_ERROR to its health monitor.
 *
 * Environment: IMA_CANBUS (bus socket), IMA_NODE_INDEX (1..3: channel A..C), IMA_NODES (1..3),
 * IMA_XCH (DDS agent socket; unset: no exchange), IMA_VOTE_THRESHOLDS ("elev,ail,rud,thr"),
 * IMA_VOTE_PERSIST, IMA_MEMBERSHIP_MISSES, and for tests only IMA_TEST_CMD_BIAS
 * ("AXIS=OFFSET@SECONDS": this replica's command on AXIS is offset from that time on). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ARINC653.h"
#include "canbus/client.h"
#include "rpas/ports.h"
#include "rpas/report.h"
#include "rpas_can.h"
#include "voter/voter.h"
#include "xch/client.h"

#define MAJOR_FRAME_NS 50000000LL
#define IO_TX_OFFSET_NS 20000000LL /* the tx window's offset in the major frame */
#define NAV_EVERY 2                /* NAV_POS / NAV_DATA every other frame (10 Hz) */

static canbus_client_t bus;
static bool connected;
static unsigned channel; /* redundancy channel: this node's replica index */
static unsigned n_nodes = 1;
static uint64_t decode_errors, unknown_frames;

/* ---- redundancy state ---- */
#define NODE_BIT(k) (1u << (k)) /* k: channel index 0..2 */
static uint32_t members;              /* NODE_BIT of every member */
static uint32_t hb_seen;              /* heartbeats seen since the last rx */
static unsigned hb_missed[XCH_MAX_NODES];
static unsigned membership_misses = 2;
static uint32_t frame_no;             /* major frame of the current rx */

static struct {
    bool have;
    double v[VOTER_MAX_DIM];
} peer_cmd[XCH_MAX_NODES], own_cmd; /* commands seen since the last rx */
static voter_t selfmon;
static bool selfmon_on, own_voted_out;
static uint32_t peers_voted_out;

static xch_client_t xch;
static bool xch_on, xch_connected;
static int64_t last_gps_t = -1, last_ahrs_t = -1, last_air_t = -1;
static voter_t in_vote[3]; /* GPS, AHRS, air data: inputs of the members */

static int bias_axis = -1;
static double bias_value;
static int64_t bias_from_ns;
static uint32_t last_fcs_mode;

static SAMPLING_PORT_ID_TYPE p_gps, p_ahrs, p_air, p_pilot, p_act, p_cmd, p_status, p_nav;

static void check(RETURN_CODE_TYPE rc, const char *what)
{
    if (rc == NO_ERROR)
        return;
    rpas_report("io: %s failed (rc=%d)", what, (int)rc);
    RETURN_CODE_TYPE r;
    SET_PARTITION_MODE(IDLE, &r);
}

static int64_t now_ns(void)
{
    SYSTEM_TIME_TYPE t;
    RETURN_CODE_TYPE rc;
    GET_TIME(&t, &rc);
    return (int64_t)t;
}

/* Connects once; a bus that is not there is reported once per attempt and tried again at the
 * next window (the flight goes on without this node's I/O meanwhile). */
static bool ensure_bus(void)
{
    if (connected)
        return true;
    const char *path = getenv("IMA_CANBUS");
    if (!path || !*path) {
        static bool told;
        if (!told)
            rpas_report("io: IMA_CANBUS is not set: no CAN bus to attach to");
        told = true;
        return false;
    }
    char name[CANBUS_NAME_LEN], err[256];
    snprintf(name, sizeof name, "node%u/io", channel + 1);
    int rc = canbus_client_connect(&bus, path, name, CANBUS_ROLE_CAN, channel + 1, err, sizeof err);
    if (rc != CANBUS_OK) {
        rpas_report("io: %s", err);
        RETURN_CODE_TYPE r;
        RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "io: CAN bus unreachable",
                                23, &r);
        return false;
    }
    connected = true;
    return true;
}

/* ---- receive: CAN -> ports ---------------------------------------------------------------- */

typedef struct {
    rpas_gps_msg_t gps;
    rpas_ahrs_msg_t ahrs;
    rpas_air_msg_t air;
    rpas_pilot_msg_t pilot;
    rpas_act_status_msg_t act;
    bool gps_pos, gps_new, ahrs_new, air_new, pilot_new, act_new;
} rx_state_t;

static rx_state_t rx;

/* A replica's command as every receiver decodes it: elev, ail, rud, thr. */
static void cmd_values(const struct rpas_can_act_cmd_a_t *m, double v[4])
{
    v[0] = rpas_can_act_cmd_a_elev_cmd_a_decode(m->elev_cmd_a);
    v[1] = rpas_can_act_cmd_a_ail_cmd_a_decode(m->ail_cmd_a);
    v[2] = rpas_can_act_cmd_a_rud_cmd_a_decode(m->rud_cmd_a);
    v[3] = rpas_can_act_cmd_a_thr_cmd_a_decode(m->thr_cmd_a);
}

static void on_frame(const struct canbus_rec *r)
{
    const uint8_t *d = r->data;
    size_t n = r->len;
    int rc = 0;
    if (!(r->flags & CANBUS_FRAME_EFF)) {
        unknown_frames++;
        return;
    }
    switch (r->id) {
    case RPAS_CAN_GPS_POS_FRAME_ID: {
        struct rpas_can_gps_pos_t m;
        if ((rc = rpas_can_gps_pos_unpack(&m, d, n)) == 0) {
            rx.gps.lat_deg = rpas_can_gps_pos_gps_lat_decode(m.gps_lat);
            rx.gps.lon_deg = rpas_can_gps_pos_gps_lon_decode(m.gps_lon);
            rx.gps_pos = true;
        }
        break;
    }
    case RPAS_CAN_GPS_VEL_FRAME_ID: {
        struct rpas_can_gps_vel_t m;
        if ((rc = rpas_can_gps_vel_unpack(&m, d, n)) == 0 && rx.gps_pos) {
            rx.gps.t_ns = r->t_ns;
            rx.gps.alt_ft = rpas_can_gps_vel_gps_alt_decode(m.gps_alt);
            rx.gps.gs_kt = rpas_can_gps_vel_gps_gs_decode(m.gps_gs);
            rx.gps.trk_deg = rpas_can_gps_vel_gps_trk_decode(m.gps_trk);
            rx.gps.fix = m.gps_fix;
            rx.gps.sats = m.gps_sats;
            rx.gps.seq = m.gps_cnt;
            rx.gps_new = true;
        }
        break;
    }
    case RPAS_CAN_AHRS_ATT_FRAME_ID: {
        struct rpas_can_ahrs_att_t m;
        if ((rc = rpas_can_ahrs_att_unpack(&m, d, n)) == 0) {
            rx.ahrs.t_ns = r->t_ns;
            rx.ahrs.roll_deg = rpas_can_ahrs_att_ahrs_roll_decode(m.ahrs_roll);
            rx.ahrs.pitch_deg = rpas_can_ahrs_att_ahrs_pitch_decode(m.ahrs_pitch);
            rx.ahrs.hdg_deg = rpas_can_ahrs_att_ahrs_hdg_decode(m.ahrs_hdg);
            rx.ahrs.status = m.ahrs_stat;
            rx.ahrs.seq = m.ahrs_cnt;
            rx.ahrs_new = true;
        }
        break;
    }
    case RPAS_CAN_AHRS_RATE_FRAME_ID: {
        struct rpas_can_ahrs_rate_t m;
        if ((rc = rpas_can_ahrs_rate_unpack(&m, d, n)) == 0) {
            rx.ahrs.p_dps = rpas_can_ahrs_rate_ahrs_p_decode(m.ahrs_p);
            rx.ahrs.q_dps = rpas_can_ahrs_rate_ahrs_q_decode(m.ahrs_q);
            rx.ahrs.r_dps = rpas_can_ahrs_rate_ahrs_r_decode(m.ahrs_r);
            rx.ahrs_new = true;
        }
        break;
    }
    case RPAS_CAN_AHRS_ACCEL_FRAME_ID: {
        struct rpas_can_ahrs_accel_t m;
        if ((rc = rpas_can_ahrs_accel_unpack(&m, d, n)) == 0) {
            rx.ahrs.ax_g = rpas_can_ahrs_accel_ahrs_ax_decode(m.ahrs_ax);
            rx.ahrs.ay_g = rpas_can_ahrs_accel_ahrs_ay_decode(m.ahrs_ay);
            rx.ahrs.az_g = rpas_can_ahrs_accel_ahrs_az_decode(m.ahrs_az);
            rx.ahrs_new = true;
        }
        break;
    }
    case RPAS_CAN_AIR_DATA_FRAME_ID: {
        struct rpas_can_air_data_t m;
        if ((rc = rpas_can_air_data_unpack(&m, d, n)) == 0) {
            rx.air.t_ns = r->t_ns;
            rx.air.ias_kt = rpas_can_air_data_adc_ias_decode(m.adc_ias);
            rx.air.alt_ft = rpas_can_air_data_adc_alt_decode(m.adc_alt);
            rx.air.vs_fpm = rpas_can_air_data_adc_vs_decode(m.adc_vs);
            rx.air.status = m.adc_stat;
            rx.air.seq = m.adc_cnt;
            rx.air_new = true;
        }
        break;
    }
    case RPAS_CAN_PILOT_MODE_FRAME_ID: {
        struct rpas_can_pilot_mode_t m;
        if ((rc = rpas_can_pilot_mode_unpack(&m, d, n)) == 0) {
            rx.pilot.t_ns = r->t_ns;
            rx.pilot.mode = m.pil_mode;
            rx.pilot.lat_mode = m.pil_lat_mode;
            rx.pilot.vert_mode = m.pil_vert_mode;
            rx.pilot_new = true;
        }
        break;
    }
    case RPAS_CAN_PILOT_TARGETS_FRAME_ID: {
        struct rpas_can_pilot_targets_t m;
        if ((rc = rpas_can_pilot_targets_unpack(&m, d, n)) == 0) {
            rx.pilot.t_ns = r->t_ns;
            rx.pilot.hdg_deg = rpas_can_pilot_targets_pil_hdg_decode(m.pil_hdg);
            rx.pilot.alt_ft = rpas_can_pilot_targets_pil_alt_decode(m.pil_alt);
            rx.pilot.ias_kt = rpas_can_pilot_targets_pil_ias_decode(m.pil_ias);
            rx.pilot.vs_fpm = rpas_can_pilot_targets_pil_vs_decode(m.pil_vs);
            rx.pilot.have_targets = 1;
            rx.pilot_new = true;
        }
        break;
    }
    case RPAS_CAN_PILOT_STICK_FRAME_ID: {
        struct rpas_can_pilot_stick_t m;
        if ((rc = rpas_can_pilot_stick_unpack(&m, d, n)) == 0) {
            rx.pilot.t_ns = r->t_ns;
            rx.pilot.t_stick_ns = r->t_ns;
            rx.pilot.stk_pitch = rpas_can_pilot_stick_stk_pitch_decode(m.stk_pitch);
            rx.pilot.stk_roll = rpas_can_pilot_stick_stk_roll_decode(m.stk_roll);
            rx.pilot.stk_yaw = rpas_can_pilot_stick_stk_yaw_decode(m.stk_yaw);
            rx.pilot.stk_thr = rpas_can_pilot_stick_stk_thr_decode(m.stk_thr);
            rx.pilot_new = true;
        }
        break;
    }
    case RPAS_CAN_ACT_STATUS_FRAME_ID: {
        struct rpas_can_act_status_t m;
        if ((rc = rpas_can_act_status_unpack(&m, d, n)) == 0) {
            rx.act.t_ns = r->t_ns;
            rx.act.elev = rpas_can_act_status_elev_pos_decode(m.elev_pos);
            rx.act.ail = rpas_can_act_status_ail_pos_decode(m.ail_pos);
            rx.act.rud = rpas_can_act_status_rud_pos_decode(m.rud_pos);
            rx.act.thr = rpas_can_act_status_thr_pos_decode(m.thr_pos);
            rx.act.state = m.act_state;
            rx.act_new = true;
        }
        break;
    }
    default:
        if (r->id >= RPAS_CAN_ACT_CMD_A_FRAME_ID && r->id < RPAS_CAN_ACT_CMD_A_FRAME_ID + XCH_MAX_NODES) {
            /* another replica's command (A, B and C share one layout) */
            unsigned ch = r->id - RPAS_CAN_ACT_CMD_A_FRAME_ID;
            struct rpas_can_act_cmd_a_t m;
            if ((rc = rpas_can_act_cmd_a_unpack(&m, d, n)) == 0 && ch < n_nodes) {
                peer_cmd[ch].have = true;
                cmd_values(&m, peer_cmd[ch].v);
            }
            break;
        }
        if (r->id >= RPAS_CAN_FCS_STATUS_A_FRAME_ID &&
            r->id < RPAS_CAN_FCS_STATUS_A_FRAME_ID + XCH_MAX_NODES) {
            hb_seen |= NODE_BIT(r->id - RPAS_CAN_FCS_STATUS_A_FRAME_ID); /* a heartbeat */
            break;
        }
        unknown_frames++; /* downlink traffic of the other replicas: not ours */
        return;
    }
    if (rc != 0)
        decode_errors++;
}

static void node_list(uint32_t mask, char *buf, size_t len)
{
    size_t at = 0;
    buf[0] = 0;
    for (unsigned k = 0; k < n_nodes && at < len; k++)
        if (mask & NODE_BIT(k))
            at += (size_t)snprintf(buf + at, len - at, "%snode%u", at ? "," : "", k + 1);
}

/* Membership from the heartbeats of the frame that ended (see the file comment). */
static void update_membership(void)
{
    uint32_t before = members;
    for (unsigned k = 0; k < n_nodes; k++) {
        if (k == channel || !(members & NODE_BIT(k)))
            continue;
        if (hb_seen & NODE_BIT(k))
            hb_missed[k] = 0;
        else if (++hb_missed[k] >= membership_misses)
            members &= ~NODE_BIT(k);
    }
    hb_seen = 0;
    if (members != before) {
        char now[64], lost[64];
        node_list(members, now, sizeof now);
        node_list(before & ~members, lost, sizeof lost);
        rpas_report("membership %s (lost %s)", now, lost);
    }
}

/* The replicas' commands of the frame that ended, voted as the actuators vote them: this
 * node's own command voted out is a fault of this replica, reported to its health monitor. */
static void self_monitor(void)
{
    if (!selfmon_on || !own_cmd.have)
        goto clear; /* nothing of ours to compare (start-up) */
    double x[VOTER_MAX_CH][VOTER_MAX_DIM] = {{0}};
    uint8_t present = 0;
    for (unsigned k = 0; k < n_nodes; k++) {
        const double *v = k == channel ? own_cmd.v : peer_cmd[k].v;
        if (k == channel || (peer_cmd[k].have && (members & NODE_BIT(k)))) {
            memcpy(x[k], v, 4 * sizeof *v);
            present |= (uint8_t)NODE_BIT(k);
        }
    }
    voter_out_t out;
    voter_step(&selfmon, (const double(*)[VOTER_MAX_DIM])x, present, &out);
    for (unsigned k = 0; k < n_nodes; k++) {
        if (!(out.newly_failed & NODE_BIT(k)))
            continue;
        const char *why = voter_reason_name((voter_reason_t)selfmon.reason[k]);
        if (k == channel) {
            own_voted_out = true;
            rpas_report("cross-channel monitor: own output voted out (%s)", why);
            RETURN_CODE_TYPE r;
            static const char msg[] = "cross-channel disagreement: own output voted out";
            RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE)msg,
                                    (ERROR_MESSAGE_SIZE_TYPE)(sizeof msg - 1), &r);
        } else {
            peers_voted_out |= NODE_BIT(k);
            rpas_report("cross-channel monitor: node%u voted out (%s)", k + 1, why);
        }
    }
    if (out.newly_disagree)
        rpas_report("cross-channel monitor: two replicas left and they disagree");
clear:
    own_cmd.have = false;
    for (unsigned k = 0; k < XCH_MAX_NODES; k++)
        peer_cmd[k].have = false;
}

static void write_port(SAMPLING_PORT_ID_TYPE port, const void *msg, size_t len)
{
    RETURN_CODE_TYPE rc;
    WRITE_SAMPLING_MESSAGE(port, (MESSAGE_ADDR_TYPE)msg, (MESSAGE_SIZE_TYPE)len, &rc);
}

static void to_inputs(struct xch_inputs *in)
{
    memset(in, 0, sizeof *in);
    if (rx.gps.t_ns > 0) {
        in->valid |= XCH_IN_GPS;
        in->gps_t_ns = rx.gps.t_ns;
        in->gps_seq = rx.gps.seq;
        in->gps_fix = rx.gps.fix;
        in->gps_sats = rx.gps.sats;
        double g[5] = {rx.gps.lat_deg, rx.gps.lon_deg, rx.gps.alt_ft, rx.gps.gs_kt, rx.gps.trk_deg};
        memcpy(in->gps, g, sizeof g);
    }
    if (rx.ahrs.t_ns > 0) {
        in->valid |= XCH_IN_AHRS;
        in->ahrs_t_ns = rx.ahrs.t_ns;
        in->ahrs_seq = rx.ahrs.seq;
        in->ahrs_status = rx.ahrs.status;
        const rpas_ahrs_msg_t *a = &rx.ahrs;
        double v[9] = {a->roll_deg, a->pitch_deg, a->hdg_deg, a->p_dps, a->q_dps,
                       a->r_dps,    a->ax_g,      a->ay_g,    a->az_g};
        memcpy(in->ahrs, v, sizeof v);
    }
    if (rx.air.t_ns > 0) {
        in->valid |= XCH_IN_AIR;
        in->air_t_ns = rx.air.t_ns;
        in->air_seq = rx.air.seq;
        in->air_status = rx.air.status;
        double v[3] = {rx.air.ias_kt, rx.air.alt_ft, rx.air.vs_fpm};
        memcpy(in->air, v, sizeof v);
    }
}

/* Sensor `which` (0 GPS, 1 AHRS, 2 air data) of a node's inputs: false if it holds none. */
static bool sample_of(const struct xch_inputs *in, unsigned which, int64_t *t, uint32_t *seq,
                      const double **values)
{
    static const uint32_t bit[3] = {XCH_IN_GPS, XCH_IN_AHRS, XCH_IN_AIR};
    if (!(in->valid & bit[which]))
        return false;
    *t = which == 0 ? in->gps_t_ns : which == 1 ? in->ahrs_t_ns : in->air_t_ns;
    *seq = which == 0 ? in->gps_seq : which == 1 ? in->ahrs_seq : in->air_seq;
    *values = which == 0 ? in->gps : which == 1 ? in->ahrs : in->air;
    return true;
}

/* One sensor's agreed sample: the newest any member holds; its values voted over the members
 * that hold that same sample. Returns the node index (0..2) whose copy carries the sample's
 * other fields, or -1 if no member holds one. */
static int agree(const struct xch_agreed *ag, unsigned which, voter_t *v, double *out, unsigned dim)
{
    int64_t t, newest = -1;
    uint32_t seq, newest_seq = 0;
    const double *values;
    int carrier = -1;
    for (unsigned k = 0; k < n_nodes; k++)
        if ((ag->present & NODE_BIT(k)) && sample_of(&ag->in[k], which, &t, &seq, &values) &&
            t > newest) {
            newest = t;
            newest_seq = seq;
            carrier = (int)k;
        }
    if (carrier < 0)
        return -1;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM] = {{0}};
    uint8_t present = 0;
    for (unsigned k = 0; k < n_nodes; k++)
        if ((ag->present & NODE_BIT(k)) && sample_of(&ag->in[k], which, &t, &seq, &values) &&
            t == newest && seq == newest_seq) {
            memcpy(x[k], values, dim * sizeof(double));
            present |= (uint8_t)NODE_BIT(k);
        }
    voter_out_t o;
    voter_step(v, (const double(*)[VOTER_MAX_DIM])x, present, &o);
    memcpy(out, o.value, dim * sizeof *out);
    return carrier;
}

/* Replaces rx's sensor samples by the agreed ones; marks the ports to write. */
static void apply_agreed(const struct xch_agreed *ag)
{
    double v[VOTER_MAX_DIM];
    int k;
    if ((k = agree(ag, 0, &in_vote[0], v, 5)) >= 0 && ag->in[k].gps_t_ns > last_gps_t) {
        const struct xch_inputs *c = &ag->in[k];
        rx.gps.t_ns = c->gps_t_ns;
        rx.gps.seq = c->gps_seq;
        rx.gps.fix = c->gps_fix;
        rx.gps.sats = c->gps_sats;
        rx.gps.lat_deg = v[0], rx.gps.lon_deg = v[1], rx.gps.alt_ft = v[2];
        rx.gps.gs_kt = v[3], rx.gps.trk_deg = v[4];
        rx.gps_new = true;
    }
    if ((k = agree(ag, 1, &in_vote[1], v, 9)) >= 0 && ag->in[k].ahrs_t_ns > last_ahrs_t) {
        const struct xch_inputs *c = &ag->in[k];
        rpas_ahrs_msg_t *a = &rx.ahrs;
        a->t_ns = c->ahrs_t_ns;
        a->seq = c->ahrs_seq;
        a->status = c->ahrs_status;
        a->roll_deg = v[0], a->pitch_deg = v[1], a->hdg_deg = v[2];
        a->p_dps = v[3], a->q_dps = v[4], a->r_dps = v[5];
        a->ax_g = v[6], a->ay_g = v[7], a->az_g = v[8];
        rx.ahrs_new = true;
    }
    if ((k = agree(ag, 2, &in_vote[2], v, 3)) >= 0 && ag->in[k].air_t_ns > last_air_t) {
        const struct xch_inputs *c = &ag->in[k];
        rx.air.t_ns = c->air_t_ns;
        rx.air.seq = c->air_seq;
        rx.air.status = c->air_status;
        rx.air.ias_kt = v[0], rx.air.alt_ft = v[1], rx.air.vs_fpm = v[2];
        rx.air_new = true;
    }
}

/* The cross-channel exchange of this frame's inputs (a no-op without an agent). */
static void exchange_inputs(int64_t t)
{
    if (!xch_on)
        return;
    if (!xch_connected) {
        char err[256];
        const char *path = getenv("IMA_XCH");
        int rc = xch_client_connect(&xch, path, channel + 1, err, sizeof err);
        if (rc != 0) {
            static bool told;
            if (!told)
                rpas_report("io: DDS agent: %s", err);
            told = true;
            return;
        }
        xch_connected = true;
    }
    struct xch_inputs mine;
    to_inputs(&mine);
    mine.wait_mask = members;
    struct xch_agreed ag;
    int rc = xch_client_exchange(&xch, frame_no, t, &mine, &ag);
    if (rc != 0) {
        rpas_report("io: cross-channel exchange failed: %s", strerror(-rc));
        xch_client_close(&xch);
        xch_connected = false;
        return;
    }
    apply_agreed(&ag);
    struct xch_health h = {.membership = members, .fcs_mode = last_fcs_mode,
                           .failed = peers_voted_out | (own_voted_out ? NODE_BIT(channel) : 0),
                           .flags = own_voted_out ? XCH_HEALTH_DISAGREE : 0};
    if (xch_client_send(&xch, XCH_HEALTH, frame_no, t, &h, sizeof h) != 0) {
        xch_client_close(&xch);
        xch_connected = false;
    }
}

static void xch_send(uint16_t type, int64_t t, const void *p, size_t len)
{
    if (xch_connected && xch_client_send(&xch, type, frame_no, t, p, len) != 0) {
        xch_client_close(&xch);
        xch_connected = false;
    }
}

static void rx_process(void)
{
    for (;;) {
        int64_t t = now_ns();
        frame_no = (uint32_t)(t / MAJOR_FRAME_NS);
        if (ensure_bus()) {
            struct canbus_rec r;
            int got;
            while ((got = canbus_client_recv(&bus, &r)) == 1)
                if (r.type == CANBUS_MSG_FRAME)
                    on_frame(&r);
            if (got < 0 && got != -ESHUTDOWN) {
                rpas_report("io: CAN bus receive failed: %s", strerror(-got));
                canbus_client_close(&bus);
                connected = false;
            }
            if (n_nodes > 1) {
                update_membership();
                self_monitor();
            }
            exchange_inputs(t);
            if (rx.gps_new) {
                write_port(p_gps, &rx.gps, sizeof rx.gps);
                last_gps_t = rx.gps.t_ns;
            }
            if (rx.ahrs_new) {
                write_port(p_ahrs, &rx.ahrs, sizeof rx.ahrs);
                last_ahrs_t = rx.ahrs.t_ns;
            }
            if (rx.air_new) {
                write_port(p_air, &rx.air, sizeof rx.air);
                last_air_t = rx.air.t_ns;
            }
            if (rx.pilot_new) {
                write_port(p_pilot, &rx.pilot, sizeof rx.pilot);
                if (rx.pilot.have_targets) {
                    /* mission data on DDS: when the targets change, and once a second */
                    static struct xch_mission last;
                    static uint32_t last_frame;
                    struct xch_mission m = {.mode = rx.pilot.mode, .lat_mode = rx.pilot.lat_mode,
                                            .vert_mode = rx.pilot.vert_mode,
                                            .hdg_deg = rx.pilot.hdg_deg, .alt_ft = rx.pilot.alt_ft,
                                            .ias_kt = rx.pilot.ias_kt, .vs_fpm = rx.pilot.vs_fpm};
                    if (memcmp(&m, &last, sizeof m) || frame_no - last_frame >= 20) {
                        xch_send(XCH_MISSION, t, &m, sizeof m);
                        last = m;
                        last_frame = frame_no;
                    }
                }
            }
            if (rx.act_new)
                write_port(p_act, &rx.act, sizeof rx.act);
            rx.gps_new = rx.ahrs_new = rx.air_new = rx.pilot_new = rx.act_new = false;
        }
        RETURN_CODE_TYPE rc;
        PERIODIC_WAIT(&rc);
    }
}

/* ---- transmit: ports -> CAN --------------------------------------------------------------- */

static double clampd(double v, double lo, double hi)
{
    if (!(v == v))
        return 0.0 < lo ? lo : (0.0 > hi ? hi : 0.0); /* NaN: the neutral value in range */
    return v < lo ? lo : (v > hi ? hi : v);
}

static double wrap360(double deg)
{
    double w = fmod(deg, 360.0);
    if (w < 0)
        w += 360.0;
    return w >= 360.0 ? 0.0 : w;
}

/* The channel's identifiers: A, B, C differ in the redundancy channel bits only. */
static uint32_t with_channel(uint32_t id_a) { return (id_a & ~0x3u) | (channel & 0x3u); }

static void send(uint32_t id, const uint8_t *data, int len, int64_t t)
{
    if (len == 8 && canbus_client_send(&bus, with_channel(id), true, data, 8, t) != 0)
        decode_errors++;
}

/* Reads a sampling port; true if a valid message of the expected size is there. */
static bool read_port(SAMPLING_PORT_ID_TYPE port, void *msg, size_t len)
{
    MESSAGE_SIZE_TYPE n;
    VALIDITY_TYPE valid;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE(port, (MESSAGE_ADDR_TYPE)msg, &n, &valid, &rc);
    return rc == NO_ERROR && valid == VALID && (size_t)n == len;
}

static void tx_process(void)
{
    uint32_t frame = 0;
    for (;;) {
        if (ensure_bus()) {
            int64_t t = now_ns();
            uint8_t buf[8];
            rpas_act_cmd_msg_t cmd;
            bool have_cmd = read_port(p_cmd, &cmd, sizeof cmd);
            if (have_cmd) {
                if (bias_axis >= 0 && t >= bias_from_ns) {
                    double *axis[4] = {&cmd.elev, &cmd.ail, &cmd.rud, &cmd.thr};
                    *axis[bias_axis] += bias_value;
                }
                struct rpas_can_act_cmd_a_t m = {
                    .elev_cmd_a = rpas_can_act_cmd_a_elev_cmd_a_encode(clampd(cmd.elev, -1, 1)),
                    .ail_cmd_a = rpas_can_act_cmd_a_ail_cmd_a_encode(clampd(cmd.ail, -1, 1)),
                    .rud_cmd_a = rpas_can_act_cmd_a_rud_cmd_a_encode(clampd(cmd.rud, -1, 1)),
                    .thr_cmd_a = rpas_can_act_cmd_a_thr_cmd_a_encode(clampd(cmd.thr, 0, 1)),
                    .cmd_cnt_a = (uint8_t)(cmd.seq & 0xF)};
                send(RPAS_CAN_ACT_CMD_A_FRAME_ID, buf, rpas_can_act_cmd_a_pack(buf, &m, sizeof buf), t);
                /* what the others receive: the command as encoded on CAN */
                own_cmd.have = true;
                cmd_values(&m, own_cmd.v);
            }
            rpas_fcs_status_msg_t st;
            bool have_st = read_port(p_status, &st, sizeof st);
            if (have_st) {
                last_fcs_mode = st.mode;
                struct rpas_can_fcs_status_a_t m = {
                    .fcs_mode_a = (uint8_t)(st.mode & 0xF),
                    .fcs_req_mode_a = (uint8_t)(st.req_mode & 0xF),
                    .fcs_fallback_a = (uint8_t)(st.fallback & 0xF),
                    .fcs_nav_flags_a = (uint8_t)(st.nav_flags & 0xF),
                    .fcs_env_flags_a = (uint8_t)(st.env_flags & 0xF),
                    .fcs_lat_mode_a = (uint8_t)(st.lat_mode & 0x3),
                    .fcs_vert_mode_a = (uint8_t)(st.vert_mode & 0x3),
                    .fcs_cnt_a = (uint8_t)frame,
                    .fcs_tgt_hdg_a = rpas_can_fcs_status_a_fcs_tgt_hdg_a_encode(wrap360(st.tgt_hdg_deg)),
                    .fcs_tgt_alt_a = rpas_can_fcs_status_a_fcs_tgt_alt_a_encode(
                        clampd(st.tgt_alt_ft, 0, 65535))};
                send(RPAS_CAN_FCS_STATUS_A_FRAME_ID, buf, rpas_can_fcs_status_a_pack(buf, &m, sizeof buf), t);
            }
            rpas_nav_msg_t nav;
            bool have_nav = read_port(p_nav, &nav, sizeof nav);
            if (xch_connected && have_nav && have_st) {
                struct xch_telemetry tm = {
                    .fcs_mode = st.mode, .fallback = st.fallback, .nav_flags = nav.flags,
                    .lat_deg = nav.lat_deg, .lon_deg = nav.lon_deg, .alt_ft = nav.alt_ft,
                    .ias_kt = nav.ias_kt, .gs_kt = nav.gs_kt, .hdg_deg = nav.hdg_deg,
                    .trk_deg = nav.trk_deg, .vs_fpm = nav.vs_fpm, .roll_deg = nav.roll_deg,
                    .pitch_deg = nav.pitch_deg};
                if (have_cmd) {
                    tm.cmd[0] = cmd.elev, tm.cmd[1] = cmd.ail, tm.cmd[2] = cmd.rud, tm.cmd[3] = cmd.thr;
                }
                xch_send(XCH_TELEMETRY, t, &tm, sizeof tm);
            }
            if (frame % NAV_EVERY == 0 && have_nav) {
                struct rpas_can_nav_pos_a_t mp = {
                    .nav_lat_a = rpas_can_nav_pos_a_nav_lat_a_encode(clampd(nav.lat_deg, -90, 90)),
                    .nav_lon_a = rpas_can_nav_pos_a_nav_lon_a_encode(clampd(nav.lon_deg, -180, 180))};
                send(RPAS_CAN_NAV_POS_A_FRAME_ID, buf, rpas_can_nav_pos_a_pack(buf, &mp, sizeof buf), t);
                double wspd = hypot(nav.wind_n_kt, nav.wind_e_kt);
                /* wind direction as reported: where it blows from */
                double wdir = wrap360(atan2(-nav.wind_e_kt, -nav.wind_n_kt) * 180.0 / M_PI);
                struct rpas_can_nav_data_a_t md = {
                    .nav_alt_a = rpas_can_nav_data_a_nav_alt_a_encode(clampd(nav.alt_ft, -83886, 83886)),
                    .nav_wind_dir_a = rpas_can_nav_data_a_nav_wind_dir_a_encode(wdir),
                    .nav_wind_spd_a = rpas_can_nav_data_a_nav_wind_spd_a_encode(clampd(wspd, 0, 204.75)),
                    .nav_gs_a = rpas_can_nav_data_a_nav_gs_a_encode(clampd(nav.gs_kt, 0, 655.35))};
                send(RPAS_CAN_NAV_DATA_A_FRAME_ID, buf, rpas_can_nav_data_a_pack(buf, &md, sizeof buf), t);
            }
            int rc = canbus_client_flush(&bus);
            if (rc != 0) {
                rpas_report("io: CAN bus send failed: %s", strerror(-rc));
                canbus_client_close(&bus);
                connected = false;
            }
        }
        frame++;
        RETURN_CODE_TYPE rc;
        PERIODIC_WAIT(&rc);
    }
}

static SAMPLING_PORT_ID_TYPE port(const char *name, size_t size, PORT_DIRECTION_TYPE dir,
                                  int64_t refresh_ns)
{
    SAMPLING_PORT_ID_TYPE id = 0;
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT((char *)name, (MESSAGE_SIZE_TYPE)size, dir, refresh_ns,
                         &id, &rc);
    check(rc, name);
    return id;
}

static void process(const char *name, void (*entry)(void), PRIORITY_TYPE prio, int64_t delay)
{
    PROCESS_ATTRIBUTE_TYPE a = {.PERIOD = MAJOR_FRAME_NS, .TIME_CAPACITY = MAJOR_FRAME_NS,
                                .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)entry, .STACK_SIZE = 65536,
                                .BASE_PRIORITY = prio, .DEADLINE = SOFT};
    snprintf(a.NAME, sizeof a.NAME, "%s", name);
    PROCESS_ID_TYPE pid;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &pid, &rc);
    check(rc, name);
    if (delay)
        DELAYED_START(pid, delay, &rc);
    else
        START(pid, &rc);
    check(rc, name);
}

/* The redundancy settings from the environment (see the file comment); bad values are
 * reported and replaced by the defaults. */
static void configure(void)
{
    const char *ch = getenv("IMA_NODE_INDEX");
    channel = ch && *ch >= '1' && *ch <= '3' && !ch[1] ? (unsigned)(*ch - '1') : 0;
    const char *nn = getenv("IMA_NODES");
    if (nn && *nn >= '1' && *nn <= '3' && !nn[1])
        n_nodes = (unsigned)(*nn - '0');
    else if (nn)
        rpas_report("io: IMA_NODES=%s is not 1..3: running as a single node", nn);
    if (channel >= n_nodes)
        n_nodes = channel + 1;
    members = (1u << n_nodes) - 1u;
    const char *mm = getenv("IMA_MEMBERSHIP_MISSES");
    if (mm) {
        char *end;
        long v = strtol(mm, &end, 10);
        if (end != mm && !*end && v >= 1 && v <= 100)
            membership_misses = (unsigned)v;
        else
            rpas_report("io: IMA_MEMBERSHIP_MISSES=%s is not 1..100: using %u", mm, membership_misses);
    }
    voter_cfg_t vc = {.n = n_nodes, .dim = 4, .persist = 3,
                      .threshold = {0.1, 0.1, 0.1, 0.1}, .safe = {0, 0, 0, 0}};
    const char *th = getenv("IMA_VOTE_THRESHOLDS");
    if (th) {
        double a[4];
        char tail;
        if (sscanf(th, "%lf,%lf,%lf,%lf%c", &a[0], &a[1], &a[2], &a[3], &tail) == 4 &&
            a[0] >= 0 && a[1] >= 0 && a[2] >= 0 && a[3] >= 0)
            memcpy(vc.threshold, a, sizeof a);
        else
            rpas_report("io: IMA_VOTE_THRESHOLDS=%s is not four thresholds >= 0", th);
    }
    const char *pe = getenv("IMA_VOTE_PERSIST");
    if (pe) {
        char *end;
        long v = strtol(pe, &end, 10);
        if (end != pe && !*end && v >= 1 && v <= 1000)
            vc.persist = (unsigned)v;
        else
            rpas_report("io: IMA_VOTE_PERSIST=%s is not 1..1000", pe);
    }
    selfmon_on = n_nodes > 1 && voter_init(&selfmon, &vc) == 0;
    /* input voting: thresholds wide enough for two copies of one sample (they agree exactly
     * when healthy); a miscompare only marks that node's input copy out of the vote */
    static const unsigned dims[3] = {5, 9, 3};
    for (int i = 0; i < 3; i++) {
        voter_cfg_t ic = {.n = n_nodes, .dim = dims[i], .persist = 1000000000u};
        for (unsigned d = 0; d < dims[i]; d++)
            ic.threshold[d] = 1e9;
        voter_init(&in_vote[i], &ic);
    }
    const char *x = getenv("IMA_XCH");
    xch_on = x && *x && n_nodes > 1;
    const char *bias = getenv("IMA_TEST_CMD_BIAS");
    if (bias) {
        static const char *axes[4] = {"elev", "ail", "rud", "thr"};
        char name[8];
        double value, from;
        char tail;
        if (sscanf(bias, "%7[a-z]=%lf@%lf%c", name, &value, &from, &tail) == 3) {
            for (int i = 0; i < 4; i++)
                if (!strcmp(name, axes[i]))
                    bias_axis = i;
        }
        if (bias_axis < 0)
            rpas_report("io: IMA_TEST_CMD_BIAS=%s is not AXIS=OFFSET@SECONDS", bias);
        else {
            bias_value = value;
            bias_from_ns = (int64_t)(from * 1e9);
            rpas_report("io: test switch: %s command offset by %g from %g s", axes[bias_axis],
                        value, from);
        }
    }
}

int main(void)
{
    configure();
    p_gps = port("GPS_OUT", sizeof(rpas_gps_msg_t), SOURCE, 600000000);
    p_ahrs = port("AHRS_OUT", sizeof(rpas_ahrs_msg_t), SOURCE, 100000000);
    p_air = port("AIR_OUT", sizeof(rpas_air_msg_t), SOURCE, 200000000);
    p_pilot = port("PILOT_OUT", sizeof(rpas_pilot_msg_t), SOURCE, 1000000000);
    p_act = port("ACT_OUT", sizeof(rpas_act_status_msg_t), SOURCE, 200000000);
    p_cmd = port("ACT_CMD_IN", sizeof(rpas_act_cmd_msg_t), DESTINATION, 200000000);
    p_status = port("FCS_STATUS_IN", sizeof(rpas_fcs_status_msg_t), DESTINATION, 200000000);
    p_nav = port("NAV_IN", sizeof(rpas_nav_msg_t), DESTINATION, 200000000);
    process("rx", rx_process, 20, 0);
    process("tx", tx_process, 10, IO_TX_OFFSET_NS);
    RETURN_CODE_TYPE rc;
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
