/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of io's CAN transmit: the frames go out on this node's redundancy channel, decode
 * (with the DBC's codecs) to what nav_fcs wrote, clamped to the DBC's ranges; the command the
 * others will see is reported; io's faults make the command wrong in their spells. */
#include <math.h>
#include <string.h>

#include "io_core.h"
#include "rpas/unit_check.h"
#include "rpas_can.h"

static io_outputs_t outputs(void)
{
    io_outputs_t o;
    memset(&o, 0, sizeof o);
    o.have_cmd = o.have_status = o.have_nav = true;
    o.cmd = (rpas_act_cmd_msg_t){.seq = 17, .elev = 0.2, .ail = -0.1, .rud = 0.05, .thr = 0.7};
    o.status = (rpas_fcs_status_msg_t){.mode = 2, .req_mode = 2, .lat_mode = 1, .tgt_hdg_deg = -90,
                                       .tgt_alt_ft = 3000};
    o.nav = (rpas_nav_msg_t){.lat_deg = 47.5, .lon_deg = -122.25, .alt_ft = 3010, .gs_kt = 110,
                             .wind_n_kt = 0, .wind_e_kt = 10};
    return o;
}

static void test_frames_on_the_node_channel(void)
{
    io_outputs_t o = outputs();
    io_frame_t f[IO_TX_MAX_FRAMES];
    double sent[IO_AXES] = {0};
    int n = io_tx_frames(&o, 2, 4, f, sent); /* channel C, an even frame: NAV too */
    CHECK(n == 4);
    CHECK(f[0].id == RPAS_CAN_ACT_CMD_C_FRAME_ID && f[1].id == RPAS_CAN_FCS_STATUS_C_FRAME_ID);
    CHECK(f[2].id == RPAS_CAN_NAV_POS_C_FRAME_ID && f[3].id == RPAS_CAN_NAV_DATA_C_FRAME_ID);
    for (int i = 0; i < n; i++)
        CHECK(f[i].len == 8);
    struct rpas_can_act_cmd_a_t c;
    CHECK(rpas_can_act_cmd_a_unpack(&c, f[0].data, 8) == 0);
    CHECK_NEAR(rpas_can_act_cmd_a_elev_cmd_a_decode(c.elev_cmd_a), 0.2, 1e-3);
    CHECK(c.cmd_cnt_a == (17 & 0xF));
    CHECK_NEAR(sent[0], rpas_can_act_cmd_a_elev_cmd_a_decode(c.elev_cmd_a), 0);
    CHECK_NEAR(sent[3], rpas_can_act_cmd_a_thr_cmd_a_decode(c.thr_cmd_a), 0);
    struct rpas_can_fcs_status_a_t s;
    CHECK(rpas_can_fcs_status_a_unpack(&s, f[1].data, 8) == 0);
    CHECK(s.fcs_mode_a == 2 && s.fcs_lat_mode_a == 1 && s.fcs_cnt_a == 4);
    CHECK_NEAR(rpas_can_fcs_status_a_fcs_tgt_hdg_a_decode(s.fcs_tgt_hdg_a), 270, 0.1); /* wrapped */
    struct rpas_can_nav_data_a_t d;
    CHECK(rpas_can_nav_data_a_unpack(&d, f[3].data, 8) == 0);
    /* the air moves east: the wind blows from the west */
    CHECK_NEAR(rpas_can_nav_data_a_nav_wind_dir_a_decode(d.nav_wind_dir_a), 270, 0.5);
    CHECK_NEAR(rpas_can_nav_data_a_nav_wind_spd_a_decode(d.nav_wind_spd_a), 10, 0.1);
    /* an odd frame: no navigation frames */
    CHECK(io_tx_frames(&o, 2, 5, f, sent) == 2);
}

/* The mission manager's status every other frame; wheel brakes only while nav_fcs brakes. */
static void test_mission_status_and_brakes(void)
{
    io_outputs_t o = outputs();
    o.have_mm = true;
    o.mm = (rpas_mm_status_msg_t){.state = RPAS_MM_CONTINGENCY, .contingency = RPAS_CT_C2_LOSS,
                                  .ct_flags = 1, .leg = 7, .phase = 2, .to_go_m = 1234.4,
                                  .xte_m = -12.34};
    io_frame_t f[IO_TX_MAX_FRAMES];
    double sent[IO_AXES] = {0};
    CHECK(io_tx_frames(&o, 1, 4, f, sent) == 5);
    CHECK(f[4].id == RPAS_CAN_MISSION_STATUS_B_FRAME_ID);
    struct rpas_can_mission_status_a_t m;
    CHECK(rpas_can_mission_status_a_unpack(&m, f[4].data, 8) == 0);
    CHECK(m.ms_state_a == RPAS_MM_CONTINGENCY && m.ms_ct_a == RPAS_CT_C2_LOSS && m.ms_leg_a == 7);
    CHECK(m.ms_phase_a == 2 && m.ms_ct_flags_a == 1);
    CHECK_NEAR(rpas_can_mission_status_a_ms_xte_a_decode(m.ms_xte_a), -12.3, 0.06);
    CHECK_NEAR(rpas_can_mission_status_a_ms_togo_a_decode(m.ms_togo_a), 1234, 0.6);
    o.mm.state = RPAS_MM_NO_PLAN, o.mm.contingency = 255, o.mm.leg = -1;
    io_tx_frames(&o, 1, 4, f, sent);
    CHECK(rpas_can_mission_status_a_unpack(&m, f[4].data, 8) == 0);
    CHECK(m.ms_ct_a == 15 && m.ms_leg_a == 255); /* none */
    o.cmd.brake = 0.5f;
    CHECK(io_tx_frames(&o, 1, 5, f, sent) == 3);
    CHECK(f[1].id == RPAS_CAN_BRAKE_CMD_B_FRAME_ID);
    struct rpas_can_brake_cmd_a_t b;
    CHECK(rpas_can_brake_cmd_a_unpack(&b, f[1].data, 8) == 0);
    CHECK_NEAR(rpas_can_brake_cmd_a_brk_cmd_a_decode(b.brk_cmd_a), 0.5, 1e-3);
}

static void test_clamped(void)
{
    io_outputs_t o = outputs();
    o.cmd.elev = 7.0;
    o.cmd.ail = NAN;
    o.cmd.thr = -3;
    o.status.tgt_hdg_deg = NAN;
    o.nav.lat_deg = 123;
    io_frame_t f[IO_TX_MAX_FRAMES];
    double sent[IO_AXES];
    io_tx_frames(&o, 0, 0, f, sent);
    CHECK_NEAR(sent[0], 1.0, 1e-3);
    CHECK_NEAR(sent[1], 0.0, 1e-3); /* NaN: the neutral value */
    CHECK_NEAR(sent[3], 0.0, 1e-3);
    struct rpas_can_fcs_status_a_t s;
    rpas_can_fcs_status_a_unpack(&s, f[1].data, 8);
    CHECK_NEAR(rpas_can_fcs_status_a_fcs_tgt_hdg_a_decode(s.fcs_tgt_hdg_a), 0, 0.1);
    struct rpas_can_nav_pos_a_t p;
    rpas_can_nav_pos_a_unpack(&p, f[2].data, 8);
    CHECK_NEAR(rpas_can_nav_pos_a_nav_lat_a_decode(p.nav_lat_a), 90, 1e-5);
}

static void test_nothing_to_send(void)
{
    io_outputs_t o;
    memset(&o, 0, sizeof o);
    io_frame_t f[IO_TX_MAX_FRAMES];
    double sent[IO_AXES] = {9, 9, 9, 9};
    CHECK(io_tx_frames(&o, 0, 0, f, sent) == 0);
    CHECK(sent[0] == 9); /* untouched without a command */
}

static void test_faults_on_the_command(void)
{
    char *argv[] = {"io", "--node=n1", "--node-index=1", "--nodes=1", "--canbus=c", "--dds=d",
                    "--vote-thresholds=0,0,0,0", "--vote-persist=1", "--membership-missed-frames=1",
                    "--test-cmd-bias=elev=0.3@0.000001",
                    "--fault=wrong_output:fid=h,at=2s,until=3s,mode=hardover,axis=thr,value=-1"};
    io_settings_t s;
    char err[200] = "";
    CHECK(io_settings_parse(&s, 11, argv, err, sizeof err) == 0);
    io_fault_state_t st;
    io_faults_init(&st);
    io_fault_reports_t rep;
    rpas_act_cmd_msg_t c = {.elev = 0.1, .thr = 0.6};
    io_cmd_faults(&s, &st, 999, &c, &rep);
    CHECK_NEAR(c.elev, 0.1, 0);
    CHECK(rep.n == 0);
    io_cmd_faults(&s, &st, 1000, &c, &rep);
    CHECK_NEAR(c.elev, 0.4, 1e-12);
    CHECK(rep.n == 1 && !strcmp(rep.line[0], "fault test-cmd-bias wrong_output applied mode=bias axis=elev value=0.3"));
    c = (rpas_act_cmd_msg_t){.elev = 0.1, .thr = 0.6};
    io_cmd_faults(&s, &st, 2000000000, &c, &rep);
    CHECK_NEAR(c.elev, 0.4, 1e-12);
    CHECK(c.thr == 0.0); /* hardover to the lower limit */
    CHECK(rep.n == 1 && strstr(rep.line[0], "fault h wrong_output applied mode=hardover axis=thr to=0"));
    io_cmd_faults(&s, &st, 3000000000, NULL, &rep); /* no command: still told the spell ended */
    CHECK(rep.n == 1 && strstr(rep.line[0], "fault h wrong_output cleared"));
}

static void test_telemetry(void)
{
    io_outputs_t o = outputs();
    struct xch_telemetry tm;
    io_telemetry(&o, &tm);
    CHECK(tm.fcs_mode == 2);
    CHECK_NEAR(tm.lat_deg, 47.5, 0);
    CHECK_NEAR(tm.cmd[3], 0.7, 0);
    o.have_cmd = false;
    io_telemetry(&o, &tm);
    CHECK(tm.cmd[3] == 0);
}

int main(void)
{
    RUN(test_frames_on_the_node_channel);
    RUN(test_mission_status_and_brakes);
    RUN(test_clamped);
    RUN(test_nothing_to_send);
    RUN(test_faults_on_the_command);
    RUN(test_telemetry);
    return UNIT_RESULT();
}
