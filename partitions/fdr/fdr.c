/* SPDX-License-Identifier: Apache-2.0 */
/* The flight data recorder's records (fdr.h). */
#include "fdr.h"

#include <string.h>

#include "rpas/crc32.h"

void fdr_init(fdr_t *f, int64_t major_frame_ns)
{
    f->seq = 0;
    f->frame_ns = major_frame_ns > 0 ? major_frame_ns : 1;
}

uint32_t fdr_crc32(const void *data, size_t len)
{
    return rpas_crc32(data, len);
}

static void seal(fdr_t *f, uint16_t kind, int64_t t_ns, const void *body, uint32_t len,
                 uint8_t out[FDR_RECORD_SIZE])
{
    memset(out, 0, FDR_RECORD_SIZE);
    fdr_header_t h = {.magic = FDR_MAGIC, .version = FDR_VERSION, .kind = kind,
                      .seq = f->seq++, .body_len = len, .t_ns = t_ns};
    memcpy(out, &h, sizeof h);
    memcpy(out + sizeof h, body, len);
    uint32_t crc = fdr_crc32(out, FDR_RECORD_SIZE - sizeof crc);
    memcpy(out + FDR_RECORD_SIZE - sizeof crc, &crc, sizeof crc);
}

void fdr_start_record(fdr_t *f, int64_t t_ns, uint32_t start_condition, uint32_t mode,
                      const char *node, uint8_t out[FDR_RECORD_SIZE])
{
    fdr_start_body_t b;
    memset(&b, 0, sizeof b);
    b.start_condition = start_condition;
    b.operating_mode = mode;
    b.record_size = FDR_RECORD_SIZE;
    if (node)
        strncpy(b.node, node, sizeof b.node - 1);
    seal(f, FDR_REC_START, t_ns, &b, sizeof b, out);
}

void fdr_frame_record(fdr_t *f, int64_t t_ns, const rpas_nav_msg_t *nav,
                      const rpas_fcs_status_msg_t *status, const rpas_mission_msg_t *mission,
                      uint8_t out[FDR_RECORD_SIZE])
{
    fdr_frame_body_t b;
    memset(&b, 0, sizeof b);
    b.frame = (uint32_t)(t_ns / f->frame_ns);
    if (nav) {
        b.nav = *nav;
        b.valid |= FDR_HAVE_NAV;
    }
    if (status) {
        b.status = *status;
        b.valid |= FDR_HAVE_STATUS;
    }
    if (mission) {
        b.mission = *mission;
        b.valid |= FDR_HAVE_MISSION;
    }
    seal(f, FDR_REC_FRAME, t_ns, &b, sizeof b, out);
}

void fdr_hm_record(fdr_t *f, int64_t t_ns, const ske_hm_log_t *hm, uint8_t out[FDR_RECORD_SIZE])
{
    seal(f, FDR_REC_HM, t_ns, hm, sizeof *hm, out);
}

bool fdr_check(const uint8_t rec[FDR_RECORD_SIZE], fdr_header_t *h)
{
    memcpy(h, rec, sizeof *h);
    uint32_t crc;
    memcpy(&crc, rec + FDR_RECORD_SIZE - sizeof crc, sizeof crc);
    if (h->magic != FDR_MAGIC || h->version != FDR_VERSION || h->body_len > FDR_BODY_MAX)
        return false;
    if (h->kind < FDR_REC_START || h->kind > FDR_REC_HM)
        return false;
    return fdr_crc32(rec, FDR_RECORD_SIZE - sizeof crc) == crc;
}
