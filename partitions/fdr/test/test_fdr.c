/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the recorder's records: layout, CRC, torn and foreign records refused. */
#include <stdio.h>
#include <string.h>

#include "fdr.h"
#include "rpas/unit_check.h"

static void test_crc_matches_the_ieee_check_value(void)
{
    CHECK(fdr_crc32("123456789", 9) == 0xcbf43926u); /* the CRC-32 check value */
    CHECK(fdr_crc32("", 0) == 0);
}

/* The table-driven CRC (rpas/crc32.h) against its definition, a bit at a time. */
static uint32_t crc_by_bits(const uint8_t *b, size_t len)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < len; i++) {
        c ^= b[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return ~c;
}

static void test_crc_matches_its_definition(void)
{
    uint8_t buf[FDR_RECORD_SIZE];
    uint32_t x = 12345;
    for (size_t i = 0; i < sizeof buf; i++) {
        x = x * 1103515245u + 12345u;
        buf[i] = (uint8_t)(x >> 16);
    }
    for (size_t n = 0; n <= sizeof buf; n += 7)
        CHECK(fdr_crc32(buf, n) == crc_by_bits(buf, n));
    for (int v = 0; v < 256; v++) {
        uint8_t one = (uint8_t)v;
        CHECK(fdr_crc32(&one, 1) == crc_by_bits(&one, 1));
    }
}

static void test_records_are_numbered_and_check(void)
{
    fdr_t f;
    fdr_init(&f, 50000000);
    uint8_t rec[FDR_RECORD_SIZE];
    fdr_header_t h;
    fdr_start_record(&f, 0, 1, 1, "node1", rec);
    CHECK(fdr_check(rec, &h) && h.kind == FDR_REC_START && h.seq == 0);
    rpas_nav_msg_t nav = {.t_ns = 100, .lat_deg = 41.5};
    rpas_fcs_status_msg_t st = {.mode = 2};
    fdr_frame_record(&f, 150000000, &nav, &st, NULL, rec);
    CHECK(fdr_check(rec, &h) && h.kind == FDR_REC_FRAME && h.seq == 1 && h.t_ns == 150000000);
    fdr_frame_body_t b;
    memcpy(&b, rec + sizeof h, sizeof b);
    CHECK(b.frame == 3 && b.valid == (FDR_HAVE_NAV | FDR_HAVE_STATUS));
    CHECK(b.nav.lat_deg == 41.5 && b.status.mode == 2);
    ske_hm_log_t hm = {.t_ns = 5, .error = 3, .len = 2};
    memcpy(hm.partition, "io", 3);
    memcpy(hm.message, "ok", 2);
    fdr_hm_record(&f, 160000000, &hm, rec);
    CHECK(fdr_check(rec, &h) && h.kind == FDR_REC_HM && h.seq == 2);
    CHECK(h.body_len == sizeof hm);
}

static void test_torn_and_foreign_records_are_refused(void)
{
    fdr_t f;
    fdr_init(&f, 50000000);
    uint8_t rec[FDR_RECORD_SIZE];
    fdr_header_t h;
    rpas_nav_msg_t nav = {.alt_ft = 3000.0};
    fdr_frame_record(&f, 0, &nav, NULL, NULL, rec);
    CHECK(fdr_check(rec, &h));
    /* torn: the tail of the record never reached the disk */
    uint8_t torn[FDR_RECORD_SIZE];
    memcpy(torn, rec, sizeof torn);
    memset(torn + 200, 0, FDR_RECORD_SIZE - 200);
    CHECK(!fdr_check(torn, &h));
    /* one bit flipped anywhere */
    for (unsigned i = 0; i < FDR_RECORD_SIZE; i += 17) {
        memcpy(torn, rec, sizeof torn);
        torn[i] ^= 0x10;
        CHECK(!fdr_check(torn, &h));
    }
    /* all zeros (a hole in a sparse file) */
    memset(torn, 0, sizeof torn);
    CHECK(!fdr_check(torn, &h));
}

int main(void)
{
    RUN(test_crc_matches_the_ieee_check_value);
    RUN(test_crc_matches_its_definition);
    RUN(test_records_are_numbered_and_check);
    RUN(test_torn_and_foreign_records_are_refused);
    return UNIT_RESULT();
}
