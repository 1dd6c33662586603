/* SPDX-License-Identifier: Apache-2.0 */
/* io's CAN receive: decodes the frames the bus delivered (sensors, pilot uplink, actuator
 * status, the other replicas' commands and heartbeats) into port messages, with the codecs
 * generated from config/can/rpas.dbc. Each sample is stamped with the end of the frame that
 * completed it, as the bus reports it. */
#include <string.h>

#include "io_core.h"
#include "rpas_can.h"

void io_rx_init(io_rx_t *rx)
{
    memset(rx, 0, sizeof *rx);
    io_uplink_init(&rx->uplink);
    rx->last_gps_t = rx->last_ahrs_t = rx->last_air_t = -1;
}

/* A replica's command as every receiver decodes it: elev, ail, rud, thr. A, B and C share
 * one layout. */
static void cmd_values(const struct rpas_can_act_cmd_a_t *m, double v[IO_AXES])
{
    v[0] = rpas_can_act_cmd_a_elev_cmd_a_decode(m->elev_cmd_a);
    v[1] = rpas_can_act_cmd_a_ail_cmd_a_decode(m->ail_cmd_a);
    v[2] = rpas_can_act_cmd_a_rud_cmd_a_decode(m->rud_cmd_a);
    v[3] = rpas_can_act_cmd_a_thr_cmd_a_decode(m->thr_cmd_a);
}

static int gps(io_rx_t *rx, const struct canbus_rec *r)
{
    int rc;
    if (r->id == RPAS_CAN_GPS_POS_FRAME_ID) {
        struct rpas_can_gps_pos_t m;
        if ((rc = rpas_can_gps_pos_unpack(&m, r->data, r->len)) == 0) {
            rx->gps.lat_deg = rpas_can_gps_pos_gps_lat_decode(m.gps_lat);
            rx->gps.lon_deg = rpas_can_gps_pos_gps_lon_decode(m.gps_lon);
            rx->gps_pos = true;
        }
        return rc;
    }
    struct rpas_can_gps_vel_t m;
    if ((rc = rpas_can_gps_vel_unpack(&m, r->data, r->len)) == 0 && rx->gps_pos) {
        rx->gps.t_ns = r->t_ns;
        rx->gps.alt_ft = rpas_can_gps_vel_gps_alt_decode(m.gps_alt);
        rx->gps.gs_kt = rpas_can_gps_vel_gps_gs_decode(m.gps_gs);
        rx->gps.trk_deg = rpas_can_gps_vel_gps_trk_decode(m.gps_trk);
        rx->gps.fix = m.gps_fix;
        rx->gps.sats = m.gps_sats;
        rx->gps.seq = m.gps_cnt;
        rx->gps_new = true;
    }
    return rc;
}

static int ahrs(io_rx_t *rx, const struct canbus_rec *r)
{
    rpas_ahrs_msg_t *a = &rx->ahrs;
    int rc;
    if (r->id == RPAS_CAN_AHRS_ATT_FRAME_ID) {
        struct rpas_can_ahrs_att_t m;
        if ((rc = rpas_can_ahrs_att_unpack(&m, r->data, r->len)) == 0) {
            a->t_ns = r->t_ns;
            a->roll_deg = rpas_can_ahrs_att_ahrs_roll_decode(m.ahrs_roll);
            a->pitch_deg = rpas_can_ahrs_att_ahrs_pitch_decode(m.ahrs_pitch);
            a->hdg_deg = rpas_can_ahrs_att_ahrs_hdg_decode(m.ahrs_hdg);
            a->status = m.ahrs_stat;
            a->seq = m.ahrs_cnt;
        }
    } else if (r->id == RPAS_CAN_AHRS_RATE_FRAME_ID) {
        struct rpas_can_ahrs_rate_t m;
        if ((rc = rpas_can_ahrs_rate_unpack(&m, r->data, r->len)) == 0) {
            a->p_dps = rpas_can_ahrs_rate_ahrs_p_decode(m.ahrs_p);
            a->q_dps = rpas_can_ahrs_rate_ahrs_q_decode(m.ahrs_q);
            a->r_dps = rpas_can_ahrs_rate_ahrs_r_decode(m.ahrs_r);
        }
    } else {
        struct rpas_can_ahrs_accel_t m;
        if ((rc = rpas_can_ahrs_accel_unpack(&m, r->data, r->len)) == 0) {
            a->ax_g = rpas_can_ahrs_accel_ahrs_ax_decode(m.ahrs_ax);
            a->ay_g = rpas_can_ahrs_accel_ahrs_ay_decode(m.ahrs_ay);
            a->az_g = rpas_can_ahrs_accel_ahrs_az_decode(m.ahrs_az);
        }
    }
    if (rc == 0)
        rx->ahrs_new = true;
    return rc;
}

static int air(io_rx_t *rx, const struct canbus_rec *r)
{
    struct rpas_can_air_data_t m;
    int rc = rpas_can_air_data_unpack(&m, r->data, r->len);
    if (rc == 0) {
        rx->air.t_ns = r->t_ns;
        rx->air.ias_kt = rpas_can_air_data_adc_ias_decode(m.adc_ias);
        rx->air.alt_ft = rpas_can_air_data_adc_alt_decode(m.adc_alt);
        rx->air.vs_fpm = rpas_can_air_data_adc_vs_decode(m.adc_vs);
        rx->air.status = m.adc_stat;
        rx->air.seq = m.adc_cnt;
        rx->air_new = true;
    }
    return rc;
}

static int pilot(io_rx_t *rx, const struct canbus_rec *r)
{
    rpas_pilot_msg_t *p = &rx->pilot;
    int rc;
    if (r->id == RPAS_CAN_PILOT_MODE_FRAME_ID) {
        struct rpas_can_pilot_mode_t m;
        if ((rc = rpas_can_pilot_mode_unpack(&m, r->data, r->len)) == 0) {
            p->mode = m.pil_mode;
            p->lat_mode = m.pil_lat_mode;
            p->vert_mode = m.pil_vert_mode;
        }
    } else if (r->id == RPAS_CAN_PILOT_TARGETS_FRAME_ID) {
        struct rpas_can_pilot_targets_t m;
        if ((rc = rpas_can_pilot_targets_unpack(&m, r->data, r->len)) == 0) {
            p->hdg_deg = rpas_can_pilot_targets_pil_hdg_decode(m.pil_hdg);
            p->alt_ft = rpas_can_pilot_targets_pil_alt_decode(m.pil_alt);
            p->ias_kt = rpas_can_pilot_targets_pil_ias_decode(m.pil_ias);
            p->vs_fpm = rpas_can_pilot_targets_pil_vs_decode(m.pil_vs);
            p->have_targets = 1;
        }
    } else {
        struct rpas_can_pilot_stick_t m;
        if ((rc = rpas_can_pilot_stick_unpack(&m, r->data, r->len)) == 0) {
            p->t_stick_ns = r->t_ns;
            p->stk_pitch = rpas_can_pilot_stick_stk_pitch_decode(m.stk_pitch);
            p->stk_roll = rpas_can_pilot_stick_stk_roll_decode(m.stk_roll);
            p->stk_yaw = rpas_can_pilot_stick_stk_yaw_decode(m.stk_yaw);
            p->stk_thr = rpas_can_pilot_stick_stk_thr_decode(m.stk_thr);
        }
    }
    if (rc == 0) {
        p->t_ns = r->t_ns;
        rx->pilot_new = true;
    }
    return rc;
}

/* The mission uplink: plan segments and the pilot's mission commands. */
static int mission(io_rx_t *rx, const struct canbus_rec *r)
{
    int rc;
    if (r->id == RPAS_CAN_MISSION_UPLOAD_FRAME_ID) {
        struct rpas_can_mission_upload_t m;
        if ((rc = rpas_can_mission_upload_unpack(&m, r->data, r->len)) == 0) {
            int ev = io_uplink_segment(&rx->uplink, m.mup_seg, m.mup_cnt, m.mup_data);
            if (ev != IO_UPLINK_NONE)
                rx->uplink_event = ev;
        }
        return rc;
    }
    struct rpas_can_mission_cmd_t m;
    if ((rc = rpas_can_mission_cmd_unpack(&m, r->data, r->len)) == 0) {
        rx->mm_cmd.cmd = m.mc_cmd;
        rx->mm_cmd.leg = m.mc_leg;
        rx->mm_cmd.cmd_seq = m.mc_cnt;
    }
    return rc;
}

static int traffic(io_rx_t *rx, const struct canbus_rec *r)
{
    struct rpas_can_traffic_t m;
    int rc = rpas_can_traffic_unpack(&m, r->data, r->len);
    if (rc == 0) {
        rpas_traffic_msg_t *t = &rx->traffic;
        t->t_ns = r->t_ns;
        t->seq = m.tfc_cnt;
        t->valid = m.tfc_valid;
        t->dn_m = rpas_can_traffic_tfc_dn_decode(m.tfc_dn);
        t->de_m = rpas_can_traffic_tfc_de_decode(m.tfc_de);
        t->dalt_ft = rpas_can_traffic_tfc_dalt_decode(m.tfc_dalt);
        t->trk_deg = rpas_can_traffic_tfc_trk_decode(m.tfc_trk);
        rx->traffic_new = true;
    }
    return rc;
}

static int radalt(io_rx_t *rx, const struct canbus_rec *r)
{
    struct rpas_can_radalt_t m;
    int rc = rpas_can_radalt_unpack(&m, r->data, r->len);
    if (rc == 0) {
        rx->radalt.t_ns = r->t_ns;
        rx->radalt.seq = m.ra_cnt;
        rx->radalt.valid = m.ra_stat;
        rx->radalt.height_ft = rpas_can_radalt_ra_hgt_decode(m.ra_hgt);
        rx->radalt_new = true;
    }
    return rc;
}

static int act_status(io_rx_t *rx, const struct canbus_rec *r)
{
    struct rpas_can_act_status_t m;
    int rc = rpas_can_act_status_unpack(&m, r->data, r->len);
    if (rc == 0) {
        rx->act.t_ns = r->t_ns;
        rx->act.elev = rpas_can_act_status_elev_pos_decode(m.elev_pos);
        rx->act.ail = rpas_can_act_status_ail_pos_decode(m.ail_pos);
        rx->act.rud = rpas_can_act_status_rud_pos_decode(m.rud_pos);
        rx->act.thr = rpas_can_act_status_thr_pos_decode(m.thr_pos);
        rx->act.state = m.act_state;
        rx->act_new = true;
    }
    return rc;
}

void io_rx_frame(io_rx_t *rx, io_peers_t *peers, unsigned n_nodes, const struct canbus_rec *r)
{
    if (!(r->flags & CANBUS_FRAME_EFF)) {
        rx->unknown_frames++;
        return;
    }
    int rc;
    switch (r->id) {
    case RPAS_CAN_GPS_POS_FRAME_ID:
    case RPAS_CAN_GPS_VEL_FRAME_ID:
        rc = gps(rx, r);
        break;
    case RPAS_CAN_AHRS_ATT_FRAME_ID:
    case RPAS_CAN_AHRS_RATE_FRAME_ID:
    case RPAS_CAN_AHRS_ACCEL_FRAME_ID:
        rc = ahrs(rx, r);
        break;
    case RPAS_CAN_AIR_DATA_FRAME_ID:
        rc = air(rx, r);
        break;
    case RPAS_CAN_PILOT_MODE_FRAME_ID:
    case RPAS_CAN_PILOT_TARGETS_FRAME_ID:
    case RPAS_CAN_PILOT_STICK_FRAME_ID:
        rc = pilot(rx, r);
        break;
    case RPAS_CAN_ACT_STATUS_FRAME_ID:
        rc = act_status(rx, r);
        break;
    case RPAS_CAN_MISSION_UPLOAD_FRAME_ID:
    case RPAS_CAN_MISSION_CMD_FRAME_ID:
        rc = mission(rx, r);
        break;
    case RPAS_CAN_TRAFFIC_FRAME_ID:
        rc = traffic(rx, r);
        break;
    case RPAS_CAN_RADALT_FRAME_ID:
        rc = radalt(rx, r);
        break;
    default:
        if (r->id >= RPAS_CAN_ACT_CMD_A_FRAME_ID && r->id < RPAS_CAN_ACT_CMD_A_FRAME_ID + XCH_MAX_NODES) {
            unsigned ch = r->id - RPAS_CAN_ACT_CMD_A_FRAME_ID;
            struct rpas_can_act_cmd_a_t m;
            if ((rc = rpas_can_act_cmd_a_unpack(&m, r->data, r->len)) == 0 && ch < n_nodes) {
                peers->cmd[ch].have = true;
                cmd_values(&m, peers->cmd[ch].v);
            }
            break;
        }
        if (r->id >= RPAS_CAN_FCS_STATUS_A_FRAME_ID &&
            r->id < RPAS_CAN_FCS_STATUS_A_FRAME_ID + XCH_MAX_NODES) {
            peers->hb_seen |= 1u << (r->id - RPAS_CAN_FCS_STATUS_A_FRAME_ID); /* a heartbeat */
            return;
        }
        rx->unknown_frames++; /* downlink traffic of the other replicas: not ours */
        return;
    }
    if (rc != 0)
        rx->decode_errors++;
}

void io_rx_written(io_rx_t *rx)
{
    if (rx->gps_new)
        rx->last_gps_t = rx->gps.t_ns;
    if (rx->ahrs_new)
        rx->last_ahrs_t = rx->ahrs.t_ns;
    if (rx->air_new)
        rx->last_air_t = rx->air.t_ns;
    rx->gps_new = rx->ahrs_new = rx->air_new = rx->pilot_new = rx->act_new = false;
    rx->traffic_new = rx->radalt_new = false;
    rx->uplink_event = IO_UPLINK_NONE;
}
