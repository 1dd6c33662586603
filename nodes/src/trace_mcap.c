/* SPDX-License-Identifier: Apache-2.0 */
/* Trace lines to MCAP message records (include/trace_mcap/trace_mcap.h). Whatever it is not
 * sure to do exactly as the recorder's Python does, it hands back (TM_PYTHON). */
#include "trace_mcap/trace_mcap.h"

#include "trace_mcap__parts.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define MAX_MESSAGES 256
#define MAX_SIGNALS 64
#define MAX_KEYS 512
#define MAX_EXTRA 256
#define MAX_KEY 64
#define MAX_DATA 64    /* CAN FD's largest payload */
#define OP_MESSAGE 0x05
#define MSG_HEAD 31    /* opcode, record length, channel, sequence, log and publish time */

typedef struct {
    uint32_t start, length;
    bool is_signed, integer; /* integer: whole scale and offset, the value is an integer */
    double scale, offset;
    char key[MAX_KEY];
    size_t key_len;
} tm_signal_t;

typedef struct {
    uint32_t id, length;
    uint16_t sig_cid;
    bool supported; /* else its frames are the Python's */
    uint32_t n;
    tm_signal_t sig[MAX_SIGNALS];
} tm_message_t;

typedef struct {
    uint32_t id;
    bool ext;
    size_t n;
    char extra[MAX_EXTRA];
} tm_key_t;

typedef struct {
    uint16_t cid;
    uint64_t *pairs;
    size_t n, cap;
} tm_entries_t;

struct tm_conv {
    int kind;
    uint16_t cid[3];
    tm_message_t *msg;
    size_t n_msg;
    tm_key_t *keys;
    size_t n_keys;
    uint8_t *out;
    size_t out_len, out_cap;
    tm_entries_t *chan;
    size_t n_chan, chan_cap;
    uint16_t *order; /* the channels with entries in this call */
    size_t n_order;
};

tm_conv_t *tm_new(int kind)
{
    if (kind != TM_CAN && kind != TM_SKE && kind != TM_FDR)
        return NULL;
    tm_conv_t *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->kind = kind;
    if (kind == TM_CAN) {
        c->msg = calloc(MAX_MESSAGES, sizeof *c->msg);
        c->keys = calloc(MAX_KEYS, sizeof *c->keys);
        if (!c->msg || !c->keys) {
            tm_free(c);
            return NULL;
        }
    }
    return c;
}

void tm_free(tm_conv_t *c)
{
    if (!c)
        return;
    for (size_t i = 0; i < c->n_chan; i++)
        free(c->chan[i].pairs);
    free(c->chan);
    free(c->order);
    free(c->out);
    free(c->msg);
    free(c->keys);
    free(c);
}

void tm_set_channel(tm_conv_t *c, int which, uint16_t cid)
{
    if (which >= 0 && which < 3)
        c->cid[which] = cid;
}

static tm_message_t *find_message(tm_conv_t *c, uint32_t id)
{
    for (size_t i = 0; i < c->n_msg; i++)
        if (c->msg[i].id == id)
            return &c->msg[i];
    return NULL;
}

int tm_can_message(tm_conv_t *c, uint32_t id, uint32_t length, uint16_t sig_cid,
                   int supported)
{
    if (c->kind != TM_CAN || length > MAX_DATA)
        return -1;
    tm_message_t *m = find_message(c, id);
    if (!m) {
        if (c->n_msg == MAX_MESSAGES)
            return -1;
        m = &c->msg[c->n_msg++];
        m->id = id;
    }
    m->length = length;
    m->sig_cid = sig_cid;
    m->supported = supported != 0;
    return 0;
}

int tm_can_signal(tm_conv_t *c, uint32_t id, uint32_t start, uint32_t length, int is_signed,
                  int integer, double scale, double offset, const char *key)
{
    tm_message_t *m = c->kind == TM_CAN ? find_message(c, id) : NULL;
    size_t n = key ? strlen(key) : 0;
    if (!m || m->n == MAX_SIGNALS || length < 1 || length > 53 || start + length > 8 * MAX_DATA ||
        n == 0 || n >= MAX_KEY)
        return -1;
    if (integer && (scale != (double)(int64_t)scale || offset != (double)(int64_t)offset ||
                    fabs(scale) > 0x1p53 || fabs(offset) > 0x1p53))
        return -1;
    tm_signal_t *s = &m->sig[m->n++];
    *s = (tm_signal_t){.start = start, .length = length, .is_signed = is_signed != 0,
                       .integer = integer != 0, .scale = scale, .offset = offset, .key_len = n};
    memcpy(s->key, key, n);
    return 0;
}

int tm_can_key(tm_conv_t *c, uint32_t id, int ext, const char *extra, size_t n)
{
    if (c->kind != TM_CAN || n > MAX_EXTRA)
        return -1;
    tm_key_t *k = NULL;
    for (size_t i = 0; i < c->n_keys && !k; i++)
        if (c->keys[i].id == id && c->keys[i].ext == (ext != 0))
            k = &c->keys[i];
    if (!k) {
        if (c->n_keys == MAX_KEYS)
            return -1;
        k = &c->keys[c->n_keys++];
        k->id = id;
        k->ext = ext != 0;
    }
    memcpy(k->extra, extra, n);
    k->n = n;
    return 0;
}

static const tm_key_t *find_key(const tm_conv_t *c, uint32_t id, bool ext)
{
    for (size_t i = 0; i < c->n_keys; i++)
        if (c->keys[i].id == id && c->keys[i].ext == ext)
            return &c->keys[i];
    return NULL;
}

/* ---- output ------------------------------------------------------------------------------ */

static bool reserve(tm_conv_t *c, size_t more)
{
    if (c->out_len + more <= c->out_cap)
        return true;
    size_t cap = c->out_cap ? c->out_cap : 1 << 16;
    while (cap < c->out_len + more)
        cap *= 2;
    uint8_t *p = realloc(c->out, cap);
    if (!p)
        return false;
    c->out = p;
    c->out_cap = cap;
    return true;
}

static void put_le(uint8_t *p, uint64_t v, int n)
{
    for (int i = 0; i < n; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* A channel's entries; the channels are listed in the order of their first message of the
 * call (as the Python writer's index would be). */
static tm_entries_t *entries_of(tm_conv_t *c, uint16_t cid)
{
    for (size_t i = 0; i < c->n_chan; i++)
        if (c->chan[i].cid == cid) {
            if (c->chan[i].n == 0)
                c->order[c->n_order++] = cid;
            return &c->chan[i];
        }
    if (c->n_chan == c->chan_cap) {
        size_t cap = c->chan_cap ? 2 * c->chan_cap : 16;
        tm_entries_t *e = realloc(c->chan, cap * sizeof *e);
        if (!e)
            return NULL;
        c->chan = e;
        uint16_t *order = realloc(c->order, cap * sizeof *order);
        if (!order)
            return NULL;
        c->order = order;
        c->chan_cap = cap;
    }
    tm_entries_t *e = &c->chan[c->n_chan++];
    *e = (tm_entries_t){.cid = cid};
    c->order[c->n_order++] = cid;
    return e;
}

/* Starts a message record of `n` data bytes: its header and index entry; the data goes to the
 * returned place. */
uint8_t *tm__message(tm_conv_t *c, uint16_t cid, uint64_t seq, uint64_t t, uint64_t base,
                     size_t n)
{
    tm_entries_t *e = entries_of(c, cid);
    if (!e || !reserve(c, MSG_HEAD + n))
        return NULL;
    if (e->n + 2 > e->cap) {
        size_t cap = e->cap ? 2 * e->cap : 256;
        uint64_t *p = realloc(e->pairs, cap * sizeof *p);
        if (!p)
            return NULL;
        e->pairs = p;
        e->cap = cap;
    }
    e->pairs[e->n++] = t;
    e->pairs[e->n++] = base + c->out_len;
    uint8_t *h = c->out + c->out_len;
    h[0] = OP_MESSAGE;
    put_le(h + 1, 22 + (uint64_t)n, 8);
    put_le(h + 9, cid, 2);
    put_le(h + 11, seq & 0xFFFFFFFFu, 4);
    put_le(h + 15, t, 8);
    put_le(h + 23, t, 8);
    c->out_len += MSG_HEAD + n;
    return h + MSG_HEAD;
}

/* The raw value of a little-endian signal. */
static uint64_t raw_bits(const uint8_t *data, uint32_t start, uint32_t length)
{
    uint64_t v = 0;
    for (uint32_t b = 0; b < length; b++) {
        uint32_t bit = start + b;
        if (data[bit / 8] >> (bit % 8) & 1)
            v |= (uint64_t)1 << b;
    }
    return v;
}

/* The signals message's JSON ({"SIG":value,...,"t_ns":T,"from":F}) into buf, its length; 0 if
 * a value has no orjson form. */
static size_t signals_json(const tm_message_t *m, const uint8_t *data, const can_line_t *l,
                           char *buf)
{
    size_t n = 0;
    buf[n++] = '{';
    for (uint32_t i = 0; i < m->n; i++) {
        const tm_signal_t *s = &m->sig[i];
        memcpy(buf + n, s->key, s->key_len);
        n += s->key_len;
        /* at most 53 bits: exact as an int64 and as a double */
        int64_t r = (int64_t)raw_bits(data, s->start, s->length);
        if (s->is_signed && (r >> (s->length - 1) & 1))
            r -= (int64_t)1 << s->length;
        if (s->integer) { /* the Python's integer arithmetic */
            int64_t v;
            if (__builtin_mul_overflow(r, (int64_t)s->scale, &v) ||
                __builtin_add_overflow(v, (int64_t)s->offset, &v))
                return 0;
            n += tm__put_i64(buf + n, v);
        } else {
            size_t k = tm_format_double((double)r * s->scale + s->offset, buf + n);
            if (!k)
                return 0;
            n += k;
        }
        buf[n++] = ',';
    }
    memcpy(buf + n, "\"t_ns\":", 7);
    n += 7;
    memcpy(buf + n, l->t_ns.s.p, l->t_ns.s.n);
    n += l->t_ns.s.n;
    memcpy(buf + n, ",\"from\":", 8);
    n += 8;
    if (l->from.type == V_STR) {
        buf[n++] = '"';
        memcpy(buf + n, l->from.s.p, l->from.s.n);
        n += l->from.s.n;
        buf[n++] = '"';
    } else {
        memcpy(buf + n, "null", 4);
        n += 4;
    }
    buf[n++] = '}';
    return n;
}

/* One bus line: 0 done, 1 the Python's, 2 full after `*part` messages, -1 no memory. */
static int can_line(tm_conv_t *c, const uint8_t *p, const uint8_t *end, uint64_t seq,
                    uint64_t base, uint64_t room, uint32_t skip, uint32_t *part)
{
    can_line_t l;
    if (!c->cid[TM_CAN_FRAMES] || !tm__read_can_line(p, end, &l))
        return 1;
    /* a can_tx frame with its time, id and formats as the bus writes them */
    if (l.kind.type != V_STR || !tm__eq(l.kind.s, "can_tx") || l.t_ns.type != V_INT || l.t_ns.neg ||
        l.id.type != V_INT || l.id.neg || tm__digits_value(l.id.s) > UINT32_MAX)
        return 1;
    if ((l.ext.type != V_NONE && l.ext.type != V_TRUE && l.ext.type != V_FALSE) ||
        (l.rtr.type != V_NONE && l.rtr.type != V_TRUE && l.rtr.type != V_FALSE) ||
        (l.data.type != V_NONE && l.data.type != V_STR) ||
        (l.from.type != V_NONE && l.from.type != V_STR && l.from.type != V_NULL))
        return 1;
    uint32_t id = (uint32_t)tm__digits_value(l.id.s);
    const tm_key_t *key = find_key(c, id, l.ext.type == V_TRUE);
    if (!key)
        return 1;
    const tm_message_t *m = find_message(c, id);
    bool signals = m && l.rtr.type != V_TRUE;
    if ((m && !m->supported) || (l.from.type == V_STR && l.from.s.n > 128))
        return 1;
    uint8_t data[MAX_DATA] = {0};
    char json[MAX_SIGNALS * (MAX_KEY + 34) + 128 + MAX_EXTRA];
    size_t json_n = 0;
    if (signals) {
        span_t hex = l.data.type == V_STR ? l.data.s : (span_t){(const uint8_t *)"", 0};
        if (!m->sig_cid || hex.n % 2 || hex.n / 2 > MAX_DATA || m->n == 0)
            return 1; /* no channel yet, an odd length (no signals) or a long one */
        for (size_t i = 0; i < hex.n / 2; i++) {
            int hi = tm__hex_digit(hex.p[2 * i]), lo = tm__hex_digit(hex.p[2 * i + 1]);
            if (hi < 0 || lo < 0)
                return 1;
            if (i < m->length)
                data[i] = (uint8_t)(hi << 4 | lo);
        }
        if (!(json_n = signals_json(m, data, &l, json)))
            return 1;
    }
    uint64_t t = tm__digits_value(l.t_ns.s);
    if (skip == 0) {
        /* the bus's line with its added fields and its record number */
        char num[24];
        size_t num_n = tm__put_u64(num, seq);
        size_t line_n = (size_t)(end - p) - 1;
        size_t n = line_n + key->n + 7 + num_n + 1;
        uint8_t *d = tm__message(c, c->cid[TM_CAN_FRAMES], seq, t, base, n);
        if (!d)
            return -1;
        memcpy(d, p, line_n);
        memcpy(d + line_n, key->extra, key->n);
        memcpy(d + line_n + key->n, ",\"seq\":", 7);
        memcpy(d + line_n + key->n + 7, num, num_n);
        d[n - 1] = '}';
        if (c->out_len >= room && signals) {
            *part = 1;
            return 2;
        }
    }
    if (signals) {
        uint8_t *d = tm__message(c, m->sig_cid, seq, t, base, json_n);
        if (!d)
            return -1;
        memcpy(d, json, json_n);
    }
    return 0;
}

/* ---- reading an SKE line ---------------------------------------------------------------------- */

static const uint8_t *find(const uint8_t *p, const uint8_t *end, const char *s)
{
    size_t n = strlen(s);
    return (size_t)(end - p) < n ? NULL : memmem(p, (size_t)(end - p), s, n);
}

static int ske_line(tm_conv_t *c, const uint8_t *p, const uint8_t *end, uint64_t seq,
                    uint64_t base)
{
    static const char head[] = "{\"t_ns\":";
    size_t len = (size_t)(end - p);
    if (len < sizeof head || memcmp(p, head, sizeof head - 1) || end[-1] != '}')
        return 1;
    const uint8_t *comma = memchr(p + 8, ',', len - 8);
    if (!comma || comma == p + 8 || (size_t)(comma - p - 8) > TM_MAX_DIGITS)
        return 1;
    for (const uint8_t *q = p + 8; q < comma; q++)
        if (*q < '0' || *q > '9')
            return 1; /* a sign, a space, an underscore: the Python's */
    uint64_t t = tm__digits_value((span_t){p + 8, (size_t)(comma - p - 8)});
    const uint8_t *k = find(p, end, "\"kind\":\"");
    span_t kind = {(const uint8_t *)"", 0};
    if (k) {
        k += 8;
        const uint8_t *q = memchr(k, '"', (size_t)(end - k));
        if (!q)
            return 1;
        kind = (span_t){k, (size_t)(q - k)};
    }
    int which = tm__eq(kind, "window_start") || tm__eq(kind, "window_end") ? TM_SKE_SCHEDULE
                : tm__eq(kind, "hm")                                    ? TM_SKE_HM
                                                                    : TM_SKE_OTHER;
    if (!c->cid[which])
        return 1;
    uint8_t *d = tm__message(c, c->cid[which], seq, t, base, len);
    if (!d)
        return -1;
    memcpy(d, p, len);
    return 0;
}

/* ---- the lines -------------------------------------------------------------------------------- */

void tm__begin(tm_conv_t *c, tm_result_t *r)
{
    c->out_len = 0;
    c->n_order = 0;
    for (size_t i = 0; i < c->n_chan; i++)
        c->chan[i].n = 0;
    *r = (tm_result_t){0};
}

void tm__end(const tm_conv_t *c, tm_result_t *r)
{
    r->out = c->out;
    r->out_len = c->out_len;
}

int tm__kind(const tm_conv_t *c)
{
    return c->kind;
}

uint16_t tm__channel(const tm_conv_t *c, int which)
{
    return c->cid[which];
}

size_t tm__out_len(const tm_conv_t *c)
{
    return c->out_len;
}

int tm_convert(tm_conv_t *c, const uint8_t *text, size_t len, uint64_t seq, uint64_t base,
               uint64_t room, uint32_t skip, tm_result_t *r)
{
    tm__begin(c, r);
    if (c->kind == TM_FDR)
        return TM_NOMEM; /* tm_fdr's: nothing done */
    int rc = TM_DONE;
    size_t pos = 0;
    while (pos < len) {
        const uint8_t *p = text + pos;
        const uint8_t *nl = memchr(p, '\n', len - pos);
        if (!nl) {
            rc = TM_PYTHON; /* not a whole line */
            break;
        }
        uint32_t part = 0;
        int v = c->kind == TM_CAN ? can_line(c, p, nl, seq, base, room, skip, &part)
                                  : ske_line(c, p, nl, seq, base);
        skip = 0;
        if (v < 0) {
            rc = TM_NOMEM;
            break;
        }
        if (v == 1) {
            rc = TM_PYTHON;
            break;
        }
        if (v == 2) {
            r->part = part;
            rc = TM_FULL;
            break;
        }
        pos = (size_t)(nl - text) + 1;
        seq++;
        r->lines++;
        if (c->out_len >= room) {
            rc = pos < len ? TM_FULL : TM_DONE;
            break;
        }
    }
    r->consumed = pos;
    tm__end(c, r);
    return rc;
}

size_t tm_channels(const tm_conv_t *c, const uint16_t **cids)
{
    *cids = c->order;
    return c->n_order;
}

size_t tm_entries(const tm_conv_t *c, uint16_t cid, const uint64_t **pairs)
{
    for (size_t i = 0; i < c->n_chan; i++)
        if (c->chan[i].cid == cid) {
            *pairs = c->chan[i].pairs;
            return c->chan[i].n;
        }
    *pairs = NULL;
    return 0;
}

uint64_t tm_count_lines(const uint8_t *text, size_t len)
{
    uint64_t n = 0;
    const uint8_t *end = text + len;
    for (const uint8_t *p = text; p < end; n++) {
        p = memchr(p, '\n', (size_t)(end - p));
        if (!p)
            break;
        p++;
    }
    return n;
}
