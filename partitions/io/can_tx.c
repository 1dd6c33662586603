/* SPDX-License-Identifier: Apache-2.0 */
/* io's CAN transmit: nav_fcs's outputs of a frame as the frames of this node's redundancy
 * channel (ACT_CMD_x, FCS_STATUS_x, NAV_POS_x, NAV_DATA_x), clamped to the DBC's ranges, and
 * the replica's telemetry for DDS. */
#include <math.h>
#include <string.h>

#include "io_core.h"
#include "rpas_can.h"

static double clampd(double v, double lo, double hi)
{
    if (isnan(v))
        return 0.0 < lo ? lo : (0.0 > hi ? hi : 0.0); /* NaN: the neutral value in range */
    return v < lo ? lo : (v > hi ? hi : v);
}

static double wrap360(double deg)
{
    if (!isfinite(deg))
        return 0.0;
    double w = fmod(deg, 360.0);
    if (w < 0)
        w += 360.0;
    return w >= 360.0 ? 0.0 : w;
}

/* The channel's identifiers: A, B, C differ in the redundancy channel bits only. */
static uint32_t with_channel(uint32_t id_a, unsigned channel) { return (id_a & ~0x3u) | (channel & 0x3u); }

static void put(io_frame_t *f, uint32_t id_a, unsigned channel, const uint8_t *data, int len)
{
    f->id = with_channel(id_a, channel);
    f->len = len == 8 ? 8 : 0; /* every message of ours is 8 bytes; 0 marks a failed pack */
    memcpy(f->data, data, 8);
}

int io_tx_frames(const io_outputs_t *o, unsigned channel, uint32_t frame,
                 io_frame_t out[IO_TX_MAX_FRAMES], double sent_cmd[IO_AXES])
{
    uint8_t buf[8];
    int n = 0;
    if (o->have_cmd) {
        const rpas_act_cmd_msg_t *c = &o->cmd;
        struct rpas_can_act_cmd_a_t m = {
            .elev_cmd_a = rpas_can_act_cmd_a_elev_cmd_a_encode(clampd(c->elev, -1, 1)),
            .ail_cmd_a = rpas_can_act_cmd_a_ail_cmd_a_encode(clampd(c->ail, -1, 1)),
            .rud_cmd_a = rpas_can_act_cmd_a_rud_cmd_a_encode(clampd(c->rud, -1, 1)),
            .thr_cmd_a = rpas_can_act_cmd_a_thr_cmd_a_encode(clampd(c->thr, 0, 1)),
            .cmd_cnt_a = (uint8_t)(c->seq & 0xF)};
        put(&out[n++], RPAS_CAN_ACT_CMD_A_FRAME_ID, channel, buf,
            rpas_can_act_cmd_a_pack(buf, &m, sizeof buf));
        /* what the others receive: the command as encoded on CAN */
        sent_cmd[0] = rpas_can_act_cmd_a_elev_cmd_a_decode(m.elev_cmd_a);
        sent_cmd[1] = rpas_can_act_cmd_a_ail_cmd_a_decode(m.ail_cmd_a);
        sent_cmd[2] = rpas_can_act_cmd_a_rud_cmd_a_decode(m.rud_cmd_a);
        sent_cmd[3] = rpas_can_act_cmd_a_thr_cmd_a_decode(m.thr_cmd_a);
        if (c->brake > 0.0f) { /* on the runway only: nothing is sent in flight */
            struct rpas_can_brake_cmd_a_t b = {
                .brk_cmd_a = rpas_can_brake_cmd_a_brk_cmd_a_encode(clampd(c->brake, 0, 1)),
                .brk_cnt_a = (uint8_t)(c->seq & 0xF)};
            put(&out[n++], RPAS_CAN_BRAKE_CMD_A_FRAME_ID, channel, buf,
                rpas_can_brake_cmd_a_pack(buf, &b, sizeof buf));
        }
    }
    if (o->have_status) {
        const rpas_fcs_status_msg_t *st = &o->status;
        struct rpas_can_fcs_status_a_t m = {
            .fcs_mode_a = (uint8_t)(st->mode & 0xF),
            .fcs_req_mode_a = (uint8_t)(st->req_mode & 0xF),
            .fcs_fallback_a = (uint8_t)(st->fallback & 0xF),
            .fcs_nav_flags_a = (uint8_t)(st->nav_flags & 0xF),
            .fcs_env_flags_a = (uint8_t)(st->env_flags & 0xF),
            .fcs_lat_mode_a = (uint8_t)(st->lat_mode & 0x3),
            .fcs_vert_mode_a = (uint8_t)(st->vert_mode & 0x3),
            .fcs_cnt_a = (uint8_t)frame,
            .fcs_tgt_hdg_a = rpas_can_fcs_status_a_fcs_tgt_hdg_a_encode(wrap360(st->tgt_hdg_deg)),
            .fcs_tgt_alt_a = rpas_can_fcs_status_a_fcs_tgt_alt_a_encode(clampd(st->tgt_alt_ft, 0, 65535))};
        put(&out[n++], RPAS_CAN_FCS_STATUS_A_FRAME_ID, channel, buf,
            rpas_can_fcs_status_a_pack(buf, &m, sizeof buf));
    }
    if (frame % IO_NAV_EVERY == 0 && o->have_nav) {
        const rpas_nav_msg_t *nav = &o->nav;
        struct rpas_can_nav_pos_a_t mp = {
            .nav_lat_a = rpas_can_nav_pos_a_nav_lat_a_encode(clampd(nav->lat_deg, -90, 90)),
            .nav_lon_a = rpas_can_nav_pos_a_nav_lon_a_encode(clampd(nav->lon_deg, -180, 180))};
        put(&out[n++], RPAS_CAN_NAV_POS_A_FRAME_ID, channel, buf,
            rpas_can_nav_pos_a_pack(buf, &mp, sizeof buf));
        double wspd = hypot(nav->wind_n_kt, nav->wind_e_kt);
        /* wind direction as reported: where it blows from */
        double wdir = wrap360(atan2(-nav->wind_e_kt, -nav->wind_n_kt) * 180.0 / M_PI);
        struct rpas_can_nav_data_a_t md = {
            .nav_alt_a = rpas_can_nav_data_a_nav_alt_a_encode(clampd(nav->alt_ft, -83886, 83886)),
            .nav_wind_dir_a = rpas_can_nav_data_a_nav_wind_dir_a_encode(wdir),
            .nav_wind_spd_a = rpas_can_nav_data_a_nav_wind_spd_a_encode(clampd(wspd, 0, 204.75)),
            .nav_gs_a = rpas_can_nav_data_a_nav_gs_a_encode(clampd(nav->gs_kt, 0, 655.35))};
        put(&out[n++], RPAS_CAN_NAV_DATA_A_FRAME_ID, channel, buf,
            rpas_can_nav_data_a_pack(buf, &md, sizeof buf));
    }
    if (frame % IO_NAV_EVERY == 0 && o->have_mm) {
        const rpas_mm_status_msg_t *mm = &o->mm;
        struct rpas_can_mission_status_a_t ms = {
            .ms_state_a = (uint8_t)(mm->state & 0xF),
            .ms_ct_a = (uint8_t)(mm->contingency < 15 ? mm->contingency : 15),
            .ms_leg_a = (uint8_t)(mm->leg >= 0 && mm->leg < 255 ? mm->leg : 255),
            .ms_xte_a = rpas_can_mission_status_a_ms_xte_a_encode(clampd(mm->xte_m, -3276.8, 3276.7)),
            .ms_togo_a = rpas_can_mission_status_a_ms_togo_a_encode(clampd(mm->to_go_m, 0, 65535)),
            .ms_phase_a = (uint8_t)(mm->phase & 0xF),
            .ms_ct_flags_a = (uint8_t)(mm->ct_flags & 0xFF),
            .ms_cnt_a = (uint8_t)((frame / IO_NAV_EVERY) & 0xF)};
        put(&out[n++], RPAS_CAN_MISSION_STATUS_A_FRAME_ID, channel, buf,
            rpas_can_mission_status_a_pack(buf, &ms, sizeof buf));
    }
    return n;
}

void io_telemetry(const io_outputs_t *o, struct xch_telemetry *tm)
{
    const rpas_nav_msg_t *nav = &o->nav;
    memset(tm, 0, sizeof *tm);
    tm->fcs_mode = o->status.mode;
    tm->fallback = o->status.fallback;
    tm->nav_flags = nav->flags;
    tm->lat_deg = nav->lat_deg, tm->lon_deg = nav->lon_deg, tm->alt_ft = nav->alt_ft;
    tm->ias_kt = nav->ias_kt, tm->gs_kt = nav->gs_kt, tm->hdg_deg = nav->hdg_deg;
    tm->trk_deg = nav->trk_deg, tm->vs_fpm = nav->vs_fpm, tm->roll_deg = nav->roll_deg;
    tm->pitch_deg = nav->pitch_deg;
    if (o->have_cmd) {
        tm->cmd[0] = o->cmd.elev, tm->cmd[1] = o->cmd.ail;
        tm->cmd[2] = o->cmd.rud, tm->cmd[3] = o->cmd.thr;
    }
}
