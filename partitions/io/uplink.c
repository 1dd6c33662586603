/* SPDX-License-Identifier: Apache-2.0 */
/* The mission plan's uplink, reassembled: the remote pilot station broadcasts the plan image
 * in MISSION_UPLOAD frames, six bytes a frame, with a fixed gap and no flow control (every
 * node receives the same frames; this is not ISO 15765-2, whose flow control needs one
 * receiver). Segment 0 announces an upload (MUP_CNT), the image's length and CRC-32; segment
 * k >= 1 carries bytes 6(k-1) .. 6k-1. A segment of another upload, out of range or a
 * duplicate is ignored; once every segment of the announced length has come the CRC decides:
 * a plan that fails it is dropped and the plan held so far stays. */
#include <string.h>

#include "io_core.h"
#include "rpas/mission_plan.h"

#define SEG_BYTES 6

void io_uplink_init(io_uplink_t *u)
{
    memset(u, 0, sizeof *u);
}

static unsigned segments(uint32_t len)
{
    return (len + SEG_BYTES - 1) / SEG_BYTES;
}

int io_uplink_segment(io_uplink_t *u, unsigned seg, unsigned cnt, uint64_t data)
{
    if (seg == 0) {
        uint32_t len = (uint32_t)(data & 0xFFFFu);
        uint32_t crc = (uint32_t)(data >> 16);
        if (len < sizeof(rpas_plan_header_t) || len > RPAS_PLAN_MAX_BYTES) {
            u->receiving = false;
            u->cnt = cnt; /* as announced, for the report */
            u->len = len;
            u->crc = crc;
            u->refused++;
            return IO_UPLINK_BAD_HEADER;
        }
        if (cnt == u->cnt && len == u->len && crc == u->crc && (u->receiving || crc == u->plan_crc))
            return IO_UPLINK_NONE; /* the same announcement again, or the plan already held */
        u->receiving = true;
        u->cnt = cnt;
        u->len = len;
        u->crc = crc;
        u->got = 0;
        memset(u->have, 0, sizeof u->have);
        return IO_UPLINK_STARTED;
    }
    if (!u->receiving || cnt != u->cnt || seg > segments(u->len))
        return IO_UPLINK_NONE;
    unsigned k = seg - 1;
    if (u->have[k / 8] & (1u << (k % 8)))
        return IO_UPLINK_NONE;
    u->have[k / 8] |= (uint8_t)(1u << (k % 8));
    u->got++;
    size_t off = (size_t)k * SEG_BYTES;
    size_t n = u->len - off < SEG_BYTES ? u->len - off : SEG_BYTES;
    for (size_t i = 0; i < n; i++)
        u->buf[off + i] = (uint8_t)(data >> (8 * i));
    if (u->got < segments(u->len))
        return IO_UPLINK_NONE;
    u->receiving = false;
    if (rpas_crc32(u->buf, u->len) != u->crc) {
        u->refused++;
        return IO_UPLINK_BAD_CRC;
    }
    memcpy(u->plan, u->buf, u->len);
    u->plan_len = u->len;
    u->plan_crc = u->crc;
    u->plan_new = true;
    return IO_UPLINK_COMPLETE;
}

uint32_t io_plan_agreement(const struct xch_agreed *ag, uint32_t members, uint32_t previous)
{
    uint32_t crc = 0;
    bool any = false;
    for (unsigned k = 0; k < XCH_MAX_NODES; k++) {
        if (!(members & (1u << k)))
            continue;
        if (!(ag->present & (1u << k)))
            return previous; /* a member not heard this frame: nothing changes */
        if (!any) {
            crc = ag->in[k].plan_crc;
            any = true;
        } else if (ag->in[k].plan_crc != crc) {
            return previous; /* the members do not hold the same plan (yet) */
        }
    }
    return any && crc ? crc : previous;
}
