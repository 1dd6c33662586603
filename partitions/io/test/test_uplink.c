/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the mission plan's uplink in io: MISSION_UPLOAD frames (packed with the DBC's
 * codecs) reassembled in any order into the plan, its CRC checked (a corrupted segment: the
 * plan held stays), duplicates and other uploads ignored, impossible lengths refused; mission
 * commands and traffic reports decoded; and the plan agreement over the members' inputs. */
#include <string.h>

#include "io_core.h"
#include "rpas/unit_check.h"
#include "rpas_can.h"

static io_rx_t rx;
static io_peers_t peers;
static uint8_t image[600];

static void send_seg(unsigned seg, unsigned cnt, uint64_t data)
{
    struct rpas_can_mission_upload_t m = {.mup_seg = (uint16_t)seg, .mup_cnt = (uint8_t)cnt,
                                          .mup_data = data};
    struct canbus_rec r = {.type = CANBUS_MSG_FRAME, .flags = CANBUS_FRAME_EFF,
                           .id = RPAS_CAN_MISSION_UPLOAD_FRAME_ID, .len = 8, .t_ns = 1000};
    CHECK(rpas_can_mission_upload_pack(r.data, &m, 8) == 8);
    io_rx_frame(&rx, &peers, 3, &r);
}

static uint64_t chunk(const uint8_t *p, size_t n)
{
    uint64_t v = 0;
    for (size_t i = 0; i < n; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

/* Sends an upload: header, then the segments in `order` (NULL: in order); flip: a segment
 * whose first byte goes out changed (0: none). */
static void upload(const uint8_t *img, uint32_t len, unsigned cnt, const unsigned *order,
                   unsigned flip)
{
    uint32_t crc = rpas_crc32(img, len);
    send_seg(0, cnt, len | ((uint64_t)crc << 16));
    unsigned n = (len + 5) / 6;
    for (unsigned i = 0; i < n; i++) {
        unsigned k = order ? order[i] : i;
        size_t left = len - 6 * k;
        uint64_t v = chunk(img + 6 * k, left < 6 ? left : 6);
        if (flip == k + 1)
            v ^= 0x01;
        send_seg(k + 1, cnt, v);
    }
}

static void reset(void)
{
    io_rx_init(&rx);
    memset(&peers, 0, sizeof peers);
    for (size_t i = 0; i < sizeof image; i++)
        image[i] = (uint8_t)(i * 7 + 3);
}

static void test_reassembly(void)
{
    reset();
    upload(image, 599, 1, NULL, 0);
    CHECK(rx.uplink_event == IO_UPLINK_COMPLETE);
    CHECK(rx.uplink.plan_new && rx.uplink.plan_len == 599);
    CHECK(rx.uplink.plan_crc == rpas_crc32(image, 599));
    CHECK(memcmp(rx.uplink.plan, image, 599) == 0);
    /* the same upload again: nothing new */
    rx.uplink.plan_new = false;
    rx.uplink_event = IO_UPLINK_NONE;
    upload(image, 599, 1, NULL, 0);
    CHECK(!rx.uplink.plan_new);
}

static void test_out_of_order_and_duplicates(void)
{
    reset();
    unsigned order[100];
    unsigned n = (300 + 5) / 6;
    for (unsigned i = 0; i < n; i++)
        order[i] = (i * 7) % n; /* 7 and 50 are coprime: a permutation */
    uint32_t crc = rpas_crc32(image, 300);
    send_seg(0, 2, 300 | ((uint64_t)crc << 16));
    send_seg(1, 2, chunk(image, 6));
    send_seg(1, 2, chunk(image, 6)); /* a duplicate */
    send_seg(3, 5, 0xDEAD);          /* another upload's: ignored */
    send_seg(n + 1, 2, 0xBEEF);      /* beyond the length: ignored */
    for (unsigned i = 0; i < n; i++)
        send_seg(order[i] + 1, 2, chunk(image + 6 * order[i], 300 - 6 * order[i] < 6 ? 300 - 6 * order[i] : 6));
    CHECK(rx.uplink_event == IO_UPLINK_COMPLETE);
    CHECK(memcmp(rx.uplink.plan, image, 300) == 0);
}

static void test_corrupted_segment_keeps_the_plan(void)
{
    reset();
    upload(image, 400, 1, NULL, 0);
    uint32_t good = rx.uplink.plan_crc;
    rx.uplink.plan_new = false;
    image[10] ^= 0xFF; /* a new plan ... */
    upload(image, 400, 2, NULL, 5); /* ... whose fifth segment is corrupted on the way */
    CHECK(rx.uplink_event == IO_UPLINK_BAD_CRC);
    CHECK(!rx.uplink.plan_new && rx.uplink.plan_crc == good);
    CHECK(rx.uplink.refused == 1);
}

static void test_bad_header(void)
{
    reset();
    send_seg(0, 1, 10 | ((uint64_t)0x1234 << 16)); /* shorter than a plan header */
    CHECK(rx.uplink_event == IO_UPLINK_BAD_HEADER);
    send_seg(0, 1, 0xFFFF);
    CHECK(rx.uplink.refused == 2 && !rx.uplink.receiving);
}

static void test_commands_and_traffic(void)
{
    reset();
    struct rpas_can_mission_cmd_t c = {.mc_cmd = RPAS_MMC_DIRECT_TO, .mc_leg = 5, .mc_cnt = 9};
    struct canbus_rec r = {.type = CANBUS_MSG_FRAME, .flags = CANBUS_FRAME_EFF,
                           .id = RPAS_CAN_MISSION_CMD_FRAME_ID, .len = 8, .t_ns = 5};
    rpas_can_mission_cmd_pack(r.data, &c, 8);
    io_rx_frame(&rx, &peers, 3, &r);
    CHECK(rx.mm_cmd.cmd == RPAS_MMC_DIRECT_TO && rx.mm_cmd.leg == 5 && rx.mm_cmd.cmd_seq == 9);
    struct rpas_can_traffic_t t = {.tfc_valid = 1, .tfc_cnt = 3,
                                   .tfc_dn = rpas_can_traffic_tfc_dn_encode(-800.0),
                                   .tfc_de = rpas_can_traffic_tfc_de_encode(120.0),
                                   .tfc_dalt = rpas_can_traffic_tfc_dalt_encode(-250.0),
                                   .tfc_trk = rpas_can_traffic_tfc_trk_encode(270.0)};
    r.id = RPAS_CAN_TRAFFIC_FRAME_ID;
    r.t_ns = 77;
    rpas_can_traffic_pack(r.data, &t, 8);
    io_rx_frame(&rx, &peers, 3, &r);
    CHECK(rx.traffic_new && rx.traffic.valid == 1 && rx.traffic.t_ns == 77);
    CHECK_NEAR(rx.traffic.dn_m, -800.0, 1e-9);
    CHECK_NEAR(rx.traffic.de_m, 120.0, 1e-9);
    CHECK_NEAR(rx.traffic.dalt_ft, -250.0, 1e-9);
    CHECK_NEAR(rx.traffic.trk_deg, 270.0, 1e-9);
}

static void test_agreement(void)
{
    struct xch_agreed ag;
    memset(&ag, 0, sizeof ag);
    ag.present = 0x7;
    ag.in[0].plan_crc = ag.in[1].plan_crc = ag.in[2].plan_crc = 0xAB;
    CHECK(io_plan_agreement(&ag, 0x7, 0) == 0xAB);
    ag.in[2].plan_crc = 0xCD; /* node3 holds another plan: nobody switches */
    CHECK(io_plan_agreement(&ag, 0x7, 0x11) == 0x11);
    CHECK(io_plan_agreement(&ag, 0x3, 0x11) == 0xAB); /* node3 is not a member */
    ag.present = 0x3; /* a member not heard this frame: nothing changes */
    CHECK(io_plan_agreement(&ag, 0x7, 0x11) == 0x11);
    ag.present = 0x7;
    ag.in[0].plan_crc = ag.in[1].plan_crc = ag.in[2].plan_crc = 0; /* nobody holds one */
    CHECK(io_plan_agreement(&ag, 0x7, 0) == 0);
}

int main(void)
{
    RUN(test_reassembly);
    RUN(test_out_of_order_and_duplicates);
    RUN(test_corrupted_segment_keeps_the_plan);
    RUN(test_bad_header);
    RUN(test_commands_and_traffic);
    RUN(test_agreement);
    return UNIT_RESULT();
}
