/* SPDX-License-Identifier: Apache-2.0 */
/* JSON-lines trace writer of the SKE. */
#include "ske__trace.h"

#include <errno.h>
#include <string.h>

int ske_trace_open(ske_trace_t *t, const char *path, const char *node)
{
    memset(t, 0, sizeof *t);
    snprintf(t->node, sizeof t->node, "%s", node);
    if (!path)
        return 0;
    if (strcmp(path, "-") == 0) {
        t->f = stdout;
        return 0;
    }
    t->f = fopen(path, "w");
    if (!t->f)
        return -errno;
    t->owned = true;
    setvbuf(t->f, NULL, _IOFBF, 1 << 16);
    return 0;
}

int ske_trace_close(ske_trace_t *t)
{
    int rc = 0;
    if (t->f) {
        if (fflush(t->f) != 0 || ferror(t->f))
            rc = -(errno ? errno : EIO);
        if (t->owned && fclose(t->f) != 0 && rc == 0)
            rc = -(errno ? errno : EIO);
    }
    t->f = NULL;
    return rc;
}

/* A piece of a line built in memory, then written with one call: fprintf's format parsing
 * and a call per character cost more than the rest of a window's bookkeeping. */
typedef struct {
    char b[256];
    size_t n;
} piece_t;

static void piece_flush(piece_t *p, FILE *f)
{
    if (p->n)
        fwrite(p->b, 1, p->n, f);
    p->n = 0;
}

static void piece_put(piece_t *p, FILE *f, const char *s, size_t n)
{
    if (p->n + n > sizeof p->b) {
        piece_flush(p, f);
        if (n > sizeof p->b) {
            fwrite(s, 1, n, f);
            return;
        }
    }
    memcpy(p->b + p->n, s, n);
    p->n += n;
}

/* A string literal, its length from its size. */
#define PIECE_LIT(p, f, lit) piece_put((p), (f), (lit), sizeof(lit) - 1)

static void piece_str(piece_t *p, FILE *f, const char *s)
{
    piece_put(p, f, s, strlen(s));
}

static void piece_i64(piece_t *p, FILE *f, int64_t v)
{
    char d[24], *e = d + sizeof d, *q = e;
    uint64_t u = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
    do {
        *--q = (char)('0' + u % 10);
        u /= 10;
    } while (u);
    if (v < 0)
        *--q = '-';
    piece_put(p, f, q, (size_t)(e - q));
}

/* ,"key": (keys are the SKE's own names: not escaped) */
static void piece_key(piece_t *p, FILE *f, const char *key)
{
    PIECE_LIT(p, f, ",\"");
    piece_str(p, f, key);
    PIECE_LIT(p, f, "\":");
}

static void piece_escaped(piece_t *p, FILE *f, const char *s, size_t len)
{
    PIECE_LIT(p, f, "\"");
    size_t from = 0;
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c != '"' && c != '\\' && c >= 0x20 && c < 0x7f)
            continue;
        piece_put(p, f, s + from, i - from);
        from = i + 1;
        char e[8];
        if (c == '"' || c == '\\') {
            e[0] = '\\';
            e[1] = (char)c;
            piece_put(p, f, e, 2);
        } else if (c == '\n') {
            PIECE_LIT(p, f, "\\n");
        } else { /* bytes, not UTF-8: keep the line valid JSON */
            static const char hex[] = "0123456789abcdef";
            memcpy(e, "\\u00", 4);
            e[4] = hex[c >> 4];
            e[5] = hex[c & 15];
            piece_put(p, f, e, 6);
        }
    }
    piece_put(p, f, s + from, len - from);
    PIECE_LIT(p, f, "\"");
}

void ske_json_escape(FILE *f, const char *s, size_t len)
{
    piece_t p = {.n = 0};
    piece_escaped(&p, f, s, len);
    piece_flush(&p, f);
}

void ske_trace_begin(ske_trace_t *t, int64_t t_ns, const char *src, const char *kind)
{
    if (!t->f)
        return;
    piece_t p = {.n = 0};
    PIECE_LIT(&p, t->f, "{\"t_ns\":");
    piece_i64(&p, t->f, t_ns);
    PIECE_LIT(&p, t->f, ",\"node\":");
    piece_escaped(&p, t->f, t->node, strlen(t->node));
    PIECE_LIT(&p, t->f, ",\"src\":");
    piece_escaped(&p, t->f, src, strlen(src));
    PIECE_LIT(&p, t->f, ",\"kind\":");
    piece_escaped(&p, t->f, kind, strlen(kind));
    piece_flush(&p, t->f);
}

void ske_trace_strn(ske_trace_t *t, const char *key, const char *val, size_t len)
{
    if (!t->f)
        return;
    piece_t p = {.n = 0};
    piece_key(&p, t->f, key);
    piece_escaped(&p, t->f, val, len);
    piece_flush(&p, t->f);
}

void ske_trace_str(ske_trace_t *t, const char *key, const char *val)
{
    ske_trace_strn(t, key, val, strlen(val));
}

void ske_trace_int(ske_trace_t *t, const char *key, int64_t v)
{
    if (!t->f)
        return;
    piece_t p = {.n = 0};
    piece_key(&p, t->f, key);
    piece_i64(&p, t->f, v);
    piece_flush(&p, t->f);
}

void ske_trace_raw(ske_trace_t *t, const char *key, const char *json)
{
    if (!t->f)
        return;
    piece_t p = {.n = 0};
    piece_key(&p, t->f, key);
    piece_str(&p, t->f, json);
    piece_flush(&p, t->f);
}

void ske_trace_bool(ske_trace_t *t, const char *key, bool v)
{
    ske_trace_raw(t, key, v ? "true" : "false");
}

void ske_trace_end(ske_trace_t *t)
{
    if (t->f)
        fwrite("}\n", 1, 2, t->f);
}

void ske_trace_maybe_flush(ske_trace_t *t, int64_t mono_ns)
{
    if (t->f && mono_ns - t->last_flush_mono_ns > 50000000LL) {
        fflush(t->f);
        t->last_flush_mono_ns = mono_ns;
    }
}
