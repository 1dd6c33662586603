/* SPDX-License-Identifier: Apache-2.0 */
/* Growable buffer and the few JSON encoders the bus trace needs, without printf. */
#include "canbus__bus.h"

#include <stdlib.h>
#include <string.h>

void canbus_sb_reserve(canbus_sbuf_t *s, size_t more)
{
    if (s->n + more <= s->cap)
        return;
    size_t cap = s->cap ? s->cap : 256;
    while (cap < s->n + more)
        cap *= 2;
    char *p = realloc(s->p, cap);
    if (!p) {
        s->oom = true;
        return;
    }
    s->p = p;
    s->cap = cap;
}

void canbus_sb_mem(canbus_sbuf_t *s, const char *p, size_t n)
{
    canbus_sb_reserve(s, n);
    if (s->n + n > s->cap)
        return;
    memcpy(s->p + s->n, p, n);
    s->n += n;
}

void canbus_sb_str(canbus_sbuf_t *s, const char *p)
{
    canbus_sb_mem(s, p, strlen(p));
}

void canbus_sb_u64(canbus_sbuf_t *s, uint64_t v)
{
    char tmp[24];
    size_t i = sizeof tmp;
    do {
        tmp[--i] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    canbus_sb_mem(s, tmp + i, sizeof tmp - i);
}

void canbus_sb_i64(canbus_sbuf_t *s, int64_t v)
{
    if (v < 0) {
        canbus_sb_mem(s, "-", 1);
        canbus_sb_u64(s, (uint64_t)0 - (uint64_t)v);
    } else
        canbus_sb_u64(s, (uint64_t)v);
}

void canbus_sb_hex(canbus_sbuf_t *s, const uint8_t *p, size_t n)
{
    static const char digits[] = "0123456789abcdef";
    canbus_sb_reserve(s, 2 * n);
    if (s->n + 2 * n > s->cap)
        return;
    for (size_t i = 0; i < n; i++) {
        s->p[s->n++] = digits[p[i] >> 4];
        s->p[s->n++] = digits[p[i] & 15];
    }
}

void canbus_sb_json_str(canbus_sbuf_t *s, const char *p, size_t n)
{
    static const char digits[] = "0123456789abcdef";
    canbus_sb_mem(s, "\"", 1);
    for (size_t i = 0; i < n && p[i]; i++) {
        unsigned char c = (unsigned char)p[i];
        if (c == '"' || c == '\\') {
            char e[2] = {'\\', (char)c};
            canbus_sb_mem(s, e, 2);
        } else if (c < 0x20 || c >= 0x7f) {
            /* Names are meant to be ASCII; anything else is shown, not trusted. */
            char e[6] = {'\\', 'u', '0', '0', digits[c >> 4], digits[c & 15]};
            canbus_sb_mem(s, e, 6);
        } else
            canbus_sb_mem(s, (const char *)&c, 1);
    }
    canbus_sb_mem(s, "\"", 1);
}

void canbus_sb_free(canbus_sbuf_t *s)
{
    free(s->p);
    memset(s, 0, sizeof *s);
}
