/* SPDX-License-Identifier: Apache-2.0 */
/* Numbers as orjson writes them, for trace_mcap.c: integers, and doubles in their shortest
 * form that reads back the same (12.34, 1e-7, 1e+16). */
#include <math.h>
#include <string.h>

#include "trace_mcap/trace_mcap.h"
#include "trace_mcap__parts.h"

size_t tm__put_u64(char *p, uint64_t v)
{
    char tmp[24];
    size_t n = 0;
    do {
        tmp[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    for (size_t i = 0; i < n; i++)
        p[i] = tmp[n - 1 - i];
    return n;
}

size_t tm__put_i64(char *p, int64_t v)
{
    if (v >= 0)
        return tm__put_u64(p, (uint64_t)v);
    p[0] = '-';
    return 1 + tm__put_u64(p + 1, (uint64_t)0 - (uint64_t)v);
}

size_t tm_format_double(double x, char *buf)
{
    if (x != x || x - x != 0)
        return 0; /* NaN, infinity */
    size_t n = 0;
    if (signbit(x)) {
        buf[n++] = '-';
        x = -x;
    }
    if (x == 0) {
        memcpy(buf + n, "0.0", 3);
        return n + 3;
    }
    char d[20];
    int k;
    size_t nd = tm__shortest(x, d, &k);
    if (k > 0 && k <= 16) {
        if ((size_t)k >= nd) { /* 1234e7 -> 12340000000.0 */
            memcpy(buf + n, d, nd);
            n += nd;
            for (size_t i = nd; i < (size_t)k; i++)
                buf[n++] = '0';
            memcpy(buf + n, ".0", 2);
            return n + 2;
        }
        memcpy(buf + n, d, (size_t)k); /* 1234e-2 -> 12.34 */
        n += (size_t)k;
        buf[n++] = '.';
        memcpy(buf + n, d + k, nd - (size_t)k);
        return n + nd - (size_t)k;
    }
    if (k <= 0 && k > -5) { /* 1234e-7 -> 0.0001234 */
        memcpy(buf + n, "0.", 2);
        n += 2;
        for (int i = 0; i < -k; i++)
            buf[n++] = '0';
        memcpy(buf + n, d, nd);
        return n + nd;
    }
    buf[n++] = d[0]; /* 1e-7, 1.5e+300 */
    if (nd > 1) {
        buf[n++] = '.';
        memcpy(buf + n, d + 1, nd - 1);
        n += nd - 1;
    }
    buf[n++] = 'e';
    int e = k - 1;
    buf[n++] = e < 0 ? '-' : '+';
    return n + tm__put_u64(buf + n, (uint64_t)(e < 0 ? -e : e));
}
