/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition (system partition, the only one with Linux I/O): bridges the avionics CAN
 * bus and the node's sampling ports. Process `rx` (every major frame, at its start) decodes the
 * frames the bus delivered into the sensor, pilot and actuator ports; process `tx` (every
 * major frame, IO_TX_OFFSET later, after nav_fcs has run) encodes nav_fcs's outputs onto CAN
 * with this node's redundancy channel. The bus socket comes from $IMA_CANBUS, the node's
 * channel (0 = A, 1 = B, 2 = C) from $IMA_NODE_INDEX. */
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

#define MAJOR_FRAME_NS 50000000LL
#define IO_TX_OFFSET_NS 20000000LL /* the tx window's offset in the major frame */
#define NAV_EVERY 2                /* NAV_POS / NAV_DATA every other frame (10 Hz) */

static canbus_client_t bus;
static bool connected;
static unsigned channel; /* redundancy channel: this node's replica index */
static uint64_t decode_errors, unknown_frames;

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
        unknown_frames++; /* other nodes' outputs and downlink traffic: not ours */
        return;
    }
    if (rc != 0)
        decode_errors++;
}

static void write_port(SAMPLING_PORT_ID_TYPE port, const void *msg, size_t len)
{
    RETURN_CODE_TYPE rc;
    WRITE_SAMPLING_MESSAGE(port, (MESSAGE_ADDR_TYPE)msg, (MESSAGE_SIZE_TYPE)len, &rc);
}

static void rx_process(void)
{
    for (;;) {
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
            if (rx.gps_new)
                write_port(p_gps, &rx.gps, sizeof rx.gps);
            if (rx.ahrs_new)
                write_port(p_ahrs, &rx.ahrs, sizeof rx.ahrs);
            if (rx.air_new)
                write_port(p_air, &rx.air, sizeof rx.air);
            if (rx.pilot_new)
                write_port(p_pilot, &rx.pilot, sizeof rx.pilot);
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
            if (read_port(p_cmd, &cmd, sizeof cmd)) {
                struct rpas_can_act_cmd_a_t m = {
                    .elev_cmd_a = rpas_can_act_cmd_a_elev_cmd_a_encode(clampd(cmd.elev, -1, 1)),
                    .ail_cmd_a = rpas_can_act_cmd_a_ail_cmd_a_encode(clampd(cmd.ail, -1, 1)),
                    .rud_cmd_a = rpas_can_act_cmd_a_rud_cmd_a_encode(clampd(cmd.rud, -1, 1)),
                    .thr_cmd_a = rpas_can_act_cmd_a_thr_cmd_a_encode(clampd(cmd.thr, 0, 1)),
                    .cmd_cnt_a = (uint8_t)(cmd.seq & 0xF)};
                send(RPAS_CAN_ACT_CMD_A_FRAME_ID, buf, rpas_can_act_cmd_a_pack(buf, &m, sizeof buf), t);
            }
            rpas_fcs_status_msg_t st;
            if (read_port(p_status, &st, sizeof st)) {
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
            if (frame % NAV_EVERY == 0 && read_port(p_nav, &nav, sizeof nav)) {
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

int main(void)
{
    const char *ch = getenv("IMA_NODE_INDEX");
    channel = ch && *ch >= '1' && *ch <= '3' && !ch[1] ? (unsigned)(*ch - '1') : 0;
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
