/* SPDX-License-Identifier: Apache-2.0 */
/* The flight data recorder's core: fixed-size records with a sequence number and a CRC-32,
 * so that a reader finds a torn tail (a record cut by a crash, or half written when the disk
 * filled) and the gaps (frames that were never recorded). No APEX, no I/O, no globals: the
 * caller owns the state and writes the bytes where it likes (main.c: the descriptor the SKE
 * opened for it). The layout is little-endian, as the host; docs/flight-data-recorder.md
 * describes it byte by byte. */
#ifndef FDR_H
#define FDR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rpas/ports.h"
#include "ske_abi.h"

#define FDR_MAGIC 0x31524446u /* "FDR1" */
#define FDR_VERSION 1u
#define FDR_RECORD_SIZE 320u

typedef enum {
    FDR_REC_START = 1, /* the recorder (re)started: body fdr_start_body_t */
    FDR_REC_FRAME = 2, /* one major frame of the node: body fdr_frame_body_t */
    FDR_REC_HM = 3, /* one health-monitor decision of the module: body ske_hm_log_t */
} fdr_kind_t;

/* Which parts of a frame record hold a message read in that frame (bits of `valid`). */
#define FDR_HAVE_NAV (1u << 0)
#define FDR_HAVE_STATUS (1u << 1)
#define FDR_HAVE_MISSION (1u << 2)

typedef struct {
    uint32_t magic;
    uint16_t version;
    uint16_t kind; /* fdr_kind_t */
    uint32_t seq; /* 0 at each start of the recorder, +1 per record */
    uint32_t body_len;
    int64_t t_ns; /* partition time the record was made */
} fdr_header_t;

typedef struct {
    uint32_t start_condition; /* APEX START_CONDITION_TYPE */
    uint32_t operating_mode; /* COLD_START or WARM_START */
    uint32_t record_size;
    uint32_t pad;
    char node[SKE_NAME_MAX];
} fdr_start_body_t;

typedef struct {
    uint32_t frame; /* t_ns / major frame */
    uint32_t valid; /* FDR_HAVE_* */
    rpas_nav_msg_t nav;
    rpas_fcs_status_msg_t status;
    rpas_mission_msg_t mission;
} fdr_frame_body_t;

/* A record: header, body, zero padding, CRC-32 of everything before it. */
#define FDR_BODY_MAX (FDR_RECORD_SIZE - sizeof(fdr_header_t) - sizeof(uint32_t))
_Static_assert(sizeof(fdr_frame_body_t) <= FDR_BODY_MAX, "a frame fits in a record");
_Static_assert(sizeof(ske_hm_log_t) <= FDR_BODY_MAX, "an HM decision fits in a record");
_Static_assert(sizeof(fdr_start_body_t) <= FDR_BODY_MAX, "a start fits in a record");

typedef struct {
    uint32_t seq; /* the next record's */
    int64_t frame_ns; /* major frame */
} fdr_t;

void fdr_init(fdr_t *f, int64_t major_frame_ns);

/* CRC-32 (IEEE 802.3, reflected, as zlib's crc32). */
uint32_t fdr_crc32(const void *data, size_t len);

/* Each fills out[FDR_RECORD_SIZE] with the next record and advances the sequence. */
void fdr_start_record(fdr_t *f, int64_t t_ns, uint32_t start_condition, uint32_t mode,
                      const char *node, uint8_t out[FDR_RECORD_SIZE]);
void fdr_frame_record(fdr_t *f, int64_t t_ns, const rpas_nav_msg_t *nav,
                      const rpas_fcs_status_msg_t *status, const rpas_mission_msg_t *mission,
                      uint8_t out[FDR_RECORD_SIZE]);
void fdr_hm_record(fdr_t *f, int64_t t_ns, const ske_hm_log_t *hm, uint8_t out[FDR_RECORD_SIZE]);

/* A reader's check of one record: true when its magic, version, kind, length and CRC hold;
 * *h then holds its header. */
bool fdr_check(const uint8_t rec[FDR_RECORD_SIZE], fdr_header_t *h);

#endif
