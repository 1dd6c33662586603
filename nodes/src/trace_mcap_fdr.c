/* SPDX-License-Identifier: Apache-2.0 */
/* A flight data recorder file's frame records to MCAP messages (tm_fdr, trace_mcap.h): the
 * JSON the recorder's Python writes for them (python/ima/recording/write.py, from
 * python/ima/fdr/records.py), byte for byte. Start and health-monitor records, rare, are the
 * Python's. */
#include <math.h>
#include <string.h>

#include "trace_mcap/trace_mcap.h"
#include "trace_mcap__parts.h"

#define FDR_RECORD 320
#define FDR_MAGIC 0x31524446u /* "FDR1" */
#define FDR_VERSION 1
#define FDR_HEADER 24 /* magic, version, kind, seq, body_len, t_ns */
#define FDR_BODY_MAX (FDR_RECORD - FDR_HEADER - 4)
#define FDR_FRAME 2
#define FRAME_BODY (8 + 112 + 72 + 56) /* frame, valid; nav, status, mission */
#define HAVE_NAV 1u
#define HAVE_STATUS 2u
#define HAVE_MISSION 4u
#define JSON_MAX 2048 /* a frame record's JSON is under 1,200 bytes */

static uint32_t crc_table[256];

static void crc_init(void)
{
    for (uint32_t i = 0; i < 256; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++)
            c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[i] = c;
    }
}

/* zlib's crc32 of p[0..n) */
static uint32_t crc32_of(const uint8_t *p, size_t n)
{
    if (!crc_table[1])
        crc_init();
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++)
        c = crc_table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

static uint32_t u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t u64(const uint8_t *p)
{
    return (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32;
}

static double f64(const uint8_t *p)
{
    uint64_t v = u64(p);
    double d;
    memcpy(&d, &v, sizeof d);
    return d;
}

typedef struct {
    char *p;
} out_t;

static void lit(out_t *o, const char *s)
{
    size_t n = strlen(s);
    memcpy(o->p, s, n);
    o->p += n;
}

static void put_u(out_t *o, const char *key, uint64_t v)
{
    lit(o, key);
    o->p += tm__put_u64(o->p, v);
}

static void put_i(out_t *o, const char *key, int64_t v)
{
    lit(o, key);
    o->p += tm__put_i64(o->p, v);
}

static void put_d(out_t *o, const char *key, double v)
{
    lit(o, key);
    size_t n = tm_format_double(v, o->p);
    if (n)
        o->p += n;
    else
        lit(o, "null"); /* NaN, infinity: as orjson writes them */
}

/* {"t_ns":..,"NAME":..,...}: an int64, then `n_int` uint32 (NULL names: padding, left out),
 * then `n_dbl` doubles, as records.py's _named() dict. */
static const uint8_t *object(out_t *o, const uint8_t *p, const char *const *ints, int n_int,
                             const char *const *dbls, int n_dbl)
{
    put_i(o, "{\"t_ns\":", (int64_t)u64(p));
    p += 8;
    for (int i = 0; i < n_int; i++, p += 4)
        if (ints[i])
            put_u(o, ints[i], u32(p));
    for (int i = 0; i < n_dbl; i++, p += 8)
        put_d(o, dbls[i], f64(p));
    lit(o, "}");
    return p;
}

static const char *const NAV_INTS[] = {",\"flags\":", NULL};
static const char *const NAV_DBLS[] = {
    ",\"lat_deg\":",  ",\"lon_deg\":",  ",\"alt_ft\":",    ",\"ias_kt\":",
    ",\"gs_kt\":",    ",\"trk_deg\":",  ",\"hdg_deg\":",   ",\"vs_fpm\":",
    ",\"roll_deg\":", ",\"pitch_deg\":", ",\"wind_n_kt\":", ",\"wind_e_kt\":"};
static const char *const STATUS_INTS[] = {",\"mode\":",     ",\"req_mode\":", ",\"fallback\":",
                                          ",\"nav_flags\":", ",\"env_flags\":", ",\"lat_mode\":",
                                          ",\"vert_mode\":", NULL};
static const char *const STATUS_DBLS[] = {",\"tgt_hdg_deg\":", ",\"tgt_alt_ft\":",
                                          ",\"tgt_ias_kt\":", ",\"tgt_vs_fpm\":"};
static const char *const MISSION_INTS[] = {",\"mode\":", ",\"lat_mode\":", ",\"vert_mode\":",
                                           ",\"flags\":"};
static const char *const MISSION_DBLS[] = {",\"hdg_deg\":", ",\"alt_ft\":", ",\"ias_kt\":",
                                           ",\"vs_fpm\":"};

/* A frame record's three messages, in their order in its body: the key, the valid bit, the
 * fields, the size (records.py: NAV, STATUS, MISSION). */
static const struct {
    const char *key;
    uint32_t have;
    const char *const *ints;
    int n_int;
    const char *const *dbls;
    int n_dbl;
    size_t size;
} PARTS[] = {
    {",\"nav\":", HAVE_NAV, NAV_INTS, 2, NAV_DBLS, 12, 112},
    {",\"status\":", HAVE_STATUS, STATUS_INTS, 8, STATUS_DBLS, 4, 72},
    {",\"mission\":", HAVE_MISSION, MISSION_INTS, 4, MISSION_DBLS, 4, 56},
};

/* The JSON of a good frame record at file offset `off`; its length. */
static size_t frame_json(const uint8_t *rec, uint64_t off, char *buf)
{
    out_t o = {buf};
    const uint8_t *body = rec + FDR_HEADER;
    uint32_t valid = u32(body + 4);
    put_u(&o, "{\"kind\":\"frame\",\"seq\":", u32(rec + 8));
    put_i(&o, ",\"t_ns\":", (int64_t)u64(rec + 16));
    put_u(&o, ",\"offset\":", off);
    put_u(&o, ",\"frame\":", u32(body));
    const uint8_t *p = body + 8;
    for (size_t i = 0; i < sizeof PARTS / sizeof PARTS[0]; i++) {
        lit(&o, PARTS[i].key);
        if (valid & PARTS[i].have)
            object(&o, p, PARTS[i].ints, PARTS[i].n_int, PARTS[i].dbls, PARTS[i].n_dbl);
        else
            lit(&o, "null");
        p += PARTS[i].size;
    }
    lit(&o, "}");
    return (size_t)(o.p - buf);
}

/* 0: torn; 1: a good frame record this code writes; 2: another record, for the Python to
 * judge and write (a start or a health-monitor record). A frame record's body too short for
 * a frame is torn, as the Python has it. */
static int classify(const uint8_t *rec)
{
    uint32_t kind = (uint32_t)rec[6] | (uint32_t)rec[7] << 8;
    uint32_t body_len = u32(rec + 12);
    if (kind != FDR_FRAME)
        return kind >= 1 && kind <= 3 ? 2 : 0;
    if (u32(rec) != FDR_MAGIC || ((uint32_t)rec[4] | (uint32_t)rec[5] << 8) != FDR_VERSION ||
        body_len > FDR_BODY_MAX || body_len < FRAME_BODY ||
        crc32_of(rec, FDR_RECORD - 4) != u32(rec + FDR_RECORD - 4))
        return 0;
    return 1;
}

int tm_fdr(tm_conv_t *c, const uint8_t *data, size_t n, size_t from, uint64_t seq,
           uint64_t base, uint64_t room, tm_result_t *r)
{
    tm__begin(c, r);
    if (tm__kind(c) != TM_FDR)
        return TM_NOMEM; /* not an FDR converter: nothing done */
    uint16_t cid = tm__channel(c, TM_FDR_RECORDS);
    int rc = TM_DONE;
    char json[JSON_MAX];
    size_t k = from;
    for (; k < n; k++) {
        const uint8_t *rec = data + k * FDR_RECORD;
        int how = classify(rec);
        if (how == 0)
            continue;
        if (how == 2 || !cid) {
            rc = TM_PYTHON;
            break;
        }
        size_t len = frame_json(rec, (uint64_t)k * FDR_RECORD, json);
        int64_t t = (int64_t)u64(rec + 16);
        uint8_t *d = tm__message(c, cid, seq + r->lines, t > 0 ? (uint64_t)t : 0, base, len);
        if (!d) {
            rc = TM_NOMEM;
            break;
        }
        memcpy(d, json, len);
        r->lines++;
        if (tm__out_len(c) >= room) { /* the chunk is full after this record, as message() has it */
            k++;
            rc = k < n ? TM_FULL : TM_DONE;
            break;
        }
    }
    r->consumed = k;
    tm__end(c, r);
    return rc;
}
