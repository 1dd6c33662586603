/* SPDX-License-Identifier: Apache-2.0 */
/* Reading a line of the bus's trace for trace_mcap.c: the flat JSON object the bus writes. */
#include <string.h>

#include "trace_mcap__parts.h"


bool tm__eq(span_t s, const char *lit)
{
    size_t n = strlen(lit);
    return s.n == n && memcmp(s.p, lit, n) == 0;
}

/* A string's content up to its closing quote: printable ASCII without escapes only (what orjson
 * would read and write back the same). */
static const uint8_t *read_string(const uint8_t *p, const uint8_t *end, span_t *out)
{
    const uint8_t *s = ++p;
    while (p < end && *p != '"') {
        if (*p < 0x20 || *p > 0x7E || *p == '\\')
            return NULL;
        p++;
    }
    if (p == end)
        return NULL;
    *out = (span_t){s, (size_t)(p - s)};
    return p + 1;
}

static const uint8_t *read_value(const uint8_t *p, const uint8_t *end, value_t *v)
{
    if (p == end)
        return NULL;
    if (*p == '"') {
        v->type = V_STR;
        return read_string(p, end, &v->s);
    }
    if (*p == '-' || (*p >= '0' && *p <= '9')) {
        v->type = V_INT;
        v->neg = *p == '-';
        if (v->neg)
            p++;
        const uint8_t *s = p;
        while (p < end && *p >= '0' && *p <= '9')
            p++;
        size_t n = (size_t)(p - s);
        if (n == 0 || n > TM_MAX_DIGITS || (n > 1 && *s == '0'))
            return NULL;
        if (p < end && (*p == '.' || *p == 'e' || *p == 'E'))
            return NULL; /* a float: the Python's */
        v->s = (span_t){s, n};
        return p;
    }
    static const struct { const char *lit; int type; } words[] = {
        {"true", V_TRUE}, {"false", V_FALSE}, {"null", V_NULL}};
    for (size_t i = 0; i < 3; i++) {
        size_t n = strlen(words[i].lit);
        if ((size_t)(end - p) >= n && memcmp(p, words[i].lit, n) == 0) {
            v->type = words[i].type;
            return p + n;
        }
    }
    return NULL; /* an object, an array, anything else */
}

/* A flat JSON object without white space, every string plain: the bus's own form. */
bool tm__read_can_line(const uint8_t *p, const uint8_t *end, can_line_t *l)
{
    memset(l, 0, sizeof *l);
    if (end - p < 2 || *p != '{' || end[-1] != '}')
        return false;
    p++;
    if (*p == '}')
        return false;
    for (;;) {
        span_t key;
        if (p == end || *p != '"' || !(p = read_string(p, end, &key)) || p == end || *p != ':')
            return false;
        value_t v = {0};
        if (!(p = read_value(p + 1, end, &v)) || p == end)
            return false;
        value_t *slot = tm__eq(key, "t_ns")   ? &l->t_ns
                        : tm__eq(key, "kind") ? &l->kind
                        : tm__eq(key, "id")   ? &l->id
                        : tm__eq(key, "ext")  ? &l->ext
                        : tm__eq(key, "rtr")  ? &l->rtr
                        : tm__eq(key, "data") ? &l->data
                        : tm__eq(key, "from") ? &l->from
                                          : NULL;
        if (slot) {
            if (slot->type != V_NONE)
                return false; /* a repeated field: the Python's */
            *slot = v;
        }
        if (*p == '}')
            return p + 1 == end;
        if (*p != ',')
            return false;
        p++;
    }
}

uint64_t tm__digits_value(span_t s)
{
    uint64_t v = 0;
    for (size_t i = 0; i < s.n; i++)
        v = 10 * v + (uint64_t)(s.p[i] - '0');
    return v;
}

int tm__hex_digit(uint8_t h)
{
    if (h >= '0' && h <= '9')
        return h - '0';
    if (h >= 'a' && h <= 'f')
        return h - 'a' + 10;
    if (h >= 'A' && h <= 'F')
        return h - 'A' + 10;
    return -1;
}
