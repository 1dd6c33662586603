// SPDX-License-Identifier: Apache-2.0
// Floats as the Python computes and writes them: % (the divisor's sign), round(x, n) (the
// nearest decimal of n places, ties to even, read back) and repr (the shortest digits that
// read back, fixed from 1e-4 to below 1e16, else d.ddde+XX with at least two exponent digits).

#include "core.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace core {

double py_mod(double x, double y)
{
    double m = std::fmod(x, y);
    if (m != 0.0) {
        if ((y < 0.0) != (m < 0.0))
            m += y;
    } else {
        m = std::copysign(0.0, y);
    }
    return m;
}

double py_round(double x, int ndigits)
{
    // glibc's printf writes the exact binary value rounded to nearest, ties to even, as
    // Python's dtoa does; strtod reads the nearest double back, as Python's does
    char buf[400];
    snprintf(buf, sizeof buf, "%.*f", ndigits, x);
    return strtod(buf, nullptr);
}

size_t py_repr(double x, char *out)
{
    // x finite
    char sci[40];
    auto r = std::to_chars(sci, sci + sizeof sci, x, std::chars_format::scientific);
    *r.ptr = '\0';
    // sci: [-]d[.ddd]e(+|-)XX
    char *p = sci;
    size_t n = 0;
    if (*p == '-')
        out[n++] = *p++;
    char *e = strchr(p, 'e');
    int exp10 = atoi(e + 1);
    char digits[20] = {0};
    size_t nd = 0;
    for (char *q = p; q < e; q++)
        if (*q != '.')
            digits[nd++] = *q;
    if (exp10 >= -5 + 1 && exp10 < 16) {
        int point = exp10 + 1;  // digits before the decimal point
        if (point <= 0) {
            out[n++] = '0';
            out[n++] = '.';
            for (int i = 0; i < -point; i++)
                out[n++] = '0';
            memcpy(out + n, digits, nd);
            n += nd;
        } else if (static_cast<size_t>(point) >= nd) {
            memcpy(out + n, digits, nd);
            n += nd;
            for (size_t i = nd; i < static_cast<size_t>(point); i++)
                out[n++] = '0';
            out[n++] = '.';
            out[n++] = '0';
        } else {
            memcpy(out + n, digits, point);
            n += point;
            out[n++] = '.';
            memcpy(out + n, digits + point, nd - point);
            n += nd - point;
        }
        return n;
    }
    out[n++] = digits[0];
    if (nd > 1) {
        out[n++] = '.';
        memcpy(out + n, digits + 1, nd - 1);
        n += nd - 1;
    }
    n += static_cast<size_t>(snprintf(out + n, 8, "e%c%02d", exp10 < 0 ? '-' : '+',
                                      exp10 < 0 ? -exp10 : exp10));
    return n;
}

size_t json_rounded(double x, int ndigits, char *out)
{
    if (x != x || std::isinf(x)) {
        memcpy(out, "null", 4);
        return 4;
    }
    double v = py_round(x, ndigits);
    if (v == 0.0)
        v = 0.0;  // no -0.0
    return py_repr(v, out);
}

}  // namespace core
