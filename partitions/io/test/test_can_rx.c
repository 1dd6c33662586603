/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of io's CAN receive: frames packed with the DBC's codecs come out as port
 * messages with the values and times they carried; frames that are not ours, or malformed,
 * are counted and change nothing. */
#include <string.h>

#include "io_core.h"
#include "rpas/unit_check.h"
#include "rpas_can.h"

static struct canbus_rec frame(uint32_t id, const uint8_t *data, int len, int64_t t_ns)
{
    struct canbus_rec r = {.type = CANBUS_MSG_FRAME, .flags = CANBUS_FRAME_EFF, .id = id, .t_ns = t_ns};
    r.len = (uint8_t)len;
    memcpy(r.data, data, 8);
    return r;
}

static io_rx_t rx;
static io_peers_t peers;

static void feed(uint32_t id, const uint8_t *data, int len, int64_t t)
{
    struct canbus_rec r = frame(id, data, len, t);
    io_rx_frame(&rx, &peers, 3, &r);
}

static void reset(void)
{
    io_rx_init(&rx);
    memset(&peers, 0, sizeof peers);
}

static void test_gps_needs_both_frames(void)
{
    reset();
    uint8_t b[8];
    struct rpas_can_gps_vel_t v = {.gps_alt = rpas_can_gps_vel_gps_alt_encode(3000.0),
                                   .gps_gs = rpas_can_gps_vel_gps_gs_encode(101.0),
                                   .gps_trk = rpas_can_gps_vel_gps_trk_encode(270.0),
                                   .gps_fix = 3, .gps_sats = 9, .gps_cnt = 5};
    int n = rpas_can_gps_vel_pack(b, &v, sizeof b);
    feed(RPAS_CAN_GPS_VEL_FRAME_ID, b, n, 1000);
    CHECK(!rx.gps_new); /* a velocity without a position is no sample */
    struct rpas_can_gps_pos_t p = {.gps_lat = rpas_can_gps_pos_gps_lat_encode(47.25),
                                   .gps_lon = rpas_can_gps_pos_gps_lon_encode(-122.5)};
    n = rpas_can_gps_pos_pack(b, &p, sizeof b);
    feed(RPAS_CAN_GPS_POS_FRAME_ID, b, n, 2000);
    n = rpas_can_gps_vel_pack(b, &v, sizeof b);
    feed(RPAS_CAN_GPS_VEL_FRAME_ID, b, n, 3000);
    CHECK(rx.gps_new);
    CHECK(rx.gps.t_ns == 3000); /* the end of the frame that completed it */
    CHECK_NEAR(rx.gps.lat_deg, 47.25, 1e-6);
    CHECK_NEAR(rx.gps.lon_deg, -122.5, 1e-6);
    CHECK_NEAR(rx.gps.alt_ft, 3000.0, 1.0);
    CHECK_NEAR(rx.gps.gs_kt, 101.0, 0.1);
    CHECK(rx.gps.fix == 3 && rx.gps.sats == 9 && rx.gps.seq == 5);
    io_rx_written(&rx);
    CHECK(!rx.gps_new && rx.last_gps_t == 3000);
}

static void test_ahrs_air_act(void)
{
    reset();
    uint8_t b[8];
    struct rpas_can_ahrs_att_t a = {.ahrs_roll = rpas_can_ahrs_att_ahrs_roll_encode(-12.5),
                                    .ahrs_pitch = rpas_can_ahrs_att_ahrs_pitch_encode(3.0),
                                    .ahrs_hdg = rpas_can_ahrs_att_ahrs_hdg_encode(181.0),
                                    .ahrs_stat = 3, .ahrs_cnt = 9};
    feed(RPAS_CAN_AHRS_ATT_FRAME_ID, b, rpas_can_ahrs_att_pack(b, &a, sizeof b), 10);
    struct rpas_can_ahrs_rate_t r = {.ahrs_q = rpas_can_ahrs_rate_ahrs_q_encode(1.5)};
    feed(RPAS_CAN_AHRS_RATE_FRAME_ID, b, rpas_can_ahrs_rate_pack(b, &r, sizeof b), 20);
    struct rpas_can_ahrs_accel_t c = {.ahrs_az = rpas_can_ahrs_accel_ahrs_az_encode(-1.0)};
    feed(RPAS_CAN_AHRS_ACCEL_FRAME_ID, b, rpas_can_ahrs_accel_pack(b, &c, sizeof b), 30);
    CHECK(rx.ahrs_new && rx.ahrs.t_ns == 10); /* stamped by the attitude frame */
    CHECK_NEAR(rx.ahrs.roll_deg, -12.5, 0.01);
    CHECK_NEAR(rx.ahrs.hdg_deg, 181.0, 0.01);
    CHECK_NEAR(rx.ahrs.q_dps, 1.5, 0.01);
    CHECK_NEAR(rx.ahrs.az_g, -1.0, 0.001);
    CHECK(rx.ahrs.status == 3 && rx.ahrs.seq == 9);

    struct rpas_can_air_data_t d = {.adc_ias = rpas_can_air_data_adc_ias_encode(99.5),
                                    .adc_alt = rpas_can_air_data_adc_alt_encode(2990),
                                    .adc_vs = rpas_can_air_data_adc_vs_encode(-300),
                                    .adc_stat = 1, .adc_cnt = 2};
    feed(RPAS_CAN_AIR_DATA_FRAME_ID, b, rpas_can_air_data_pack(b, &d, sizeof b), 40);
    CHECK(rx.air_new && rx.air.t_ns == 40);
    CHECK_NEAR(rx.air.ias_kt, 99.5, 0.1);
    CHECK_NEAR(rx.air.vs_fpm, -300, 10);

    struct rpas_can_act_status_t s = {.elev_pos = rpas_can_act_status_elev_pos_encode(-0.25),
                                      .thr_pos = rpas_can_act_status_thr_pos_encode(0.7),
                                      .act_state = 1};
    feed(RPAS_CAN_ACT_STATUS_FRAME_ID, b, rpas_can_act_status_pack(b, &s, sizeof b), 50);
    CHECK(rx.act_new && rx.act.t_ns == 50 && rx.act.state == 1);
    CHECK_NEAR(rx.act.elev, -0.25, 0.01);
    CHECK_NEAR(rx.act.thr, 0.7, 0.01);
}

static void test_pilot(void)
{
    reset();
    uint8_t b[8];
    struct rpas_can_pilot_mode_t m = {.pil_mode = 2, .pil_lat_mode = 1, .pil_vert_mode = 1};
    feed(RPAS_CAN_PILOT_MODE_FRAME_ID, b, rpas_can_pilot_mode_pack(b, &m, sizeof b), 100);
    CHECK(rx.pilot_new && rx.pilot.mode == 2 && rx.pilot.lat_mode == 1 && !rx.pilot.have_targets);
    struct rpas_can_pilot_targets_t t = {.pil_hdg = rpas_can_pilot_targets_pil_hdg_encode(90),
                                         .pil_alt = rpas_can_pilot_targets_pil_alt_encode(3500),
                                         .pil_ias = rpas_can_pilot_targets_pil_ias_encode(95)};
    feed(RPAS_CAN_PILOT_TARGETS_FRAME_ID, b, rpas_can_pilot_targets_pack(b, &t, sizeof b), 200);
    CHECK(rx.pilot.have_targets && rx.pilot.t_ns == 200);
    CHECK_NEAR(rx.pilot.alt_ft, 3500, 1);
    struct rpas_can_pilot_stick_t s = {.stk_pitch = rpas_can_pilot_stick_stk_pitch_encode(0.5)};
    feed(RPAS_CAN_PILOT_STICK_FRAME_ID, b, rpas_can_pilot_stick_pack(b, &s, sizeof b), 300);
    CHECK(rx.pilot.t_stick_ns == 300 && rx.pilot.t_ns == 300);
    CHECK_NEAR(rx.pilot.stk_pitch, 0.5, 0.01);
}

static void test_replicas(void)
{
    reset();
    uint8_t b[8];
    struct rpas_can_act_cmd_a_t c = {.elev_cmd_a = rpas_can_act_cmd_a_elev_cmd_a_encode(0.125),
                                     .thr_cmd_a = rpas_can_act_cmd_a_thr_cmd_a_encode(0.75)};
    int n = rpas_can_act_cmd_a_pack(b, &c, sizeof b);
    feed(RPAS_CAN_ACT_CMD_B_FRAME_ID, b, n, 5); /* B and C share A's layout */
    CHECK(peers.cmd[1].have && !peers.cmd[0].have);
    CHECK_NEAR(peers.cmd[1].v[0], 0.125, 1e-3);
    CHECK_NEAR(peers.cmd[1].v[3], 0.75, 1e-3);
    feed(RPAS_CAN_FCS_STATUS_C_FRAME_ID, b, 8, 6);
    CHECK(peers.hb_seen == 4u);
    CHECK(rx.decode_errors == 0 && rx.unknown_frames == 0);
}

static void test_not_ours(void)
{
    reset();
    uint8_t b[8] = {0};
    struct canbus_rec std = frame(RPAS_CAN_AIR_DATA_FRAME_ID, b, 8, 1);
    std.flags = 0; /* an 11-bit identifier: not an ARINC 825 frame */
    io_rx_frame(&rx, &peers, 3, &std);
    feed(RPAS_CAN_NAV_POS_B_FRAME_ID, b, 8, 2); /* another replica's downlink */
    feed(0x1234567, b, 8, 3);
    CHECK(rx.unknown_frames == 3);
    feed(RPAS_CAN_AIR_DATA_FRAME_ID, b, 3, 4); /* too short for its layout */
    CHECK(rx.decode_errors == 1);
    CHECK(!rx.air_new && !rx.gps_new && !rx.ahrs_new && !rx.pilot_new && !rx.act_new);
    /* a replica beyond the system's nodes is not recorded */
    struct canbus_rec r = frame(RPAS_CAN_ACT_CMD_C_FRAME_ID, b, 8, 5);
    io_rx_frame(&rx, &peers, 2, &r);
    CHECK(!peers.cmd[2].have);
}

int main(void)
{
    RUN(test_gps_needs_both_frames);
    RUN(test_ahrs_air_act);
    RUN(test_pilot);
    RUN(test_replicas);
    RUN(test_not_ours);
    return UNIT_RESULT();
}
