// SPDX-License-Identifier: Apache-2.0
// The shortest decimal digits of a double that read back as it: C++17's std::to_chars (the
// Ryu algorithm in libstdc++), for trace_mcap.c, which lays them out as orjson does.
#include <charconv>
#include <cstdlib>

#include "trace_mcap__parts.h"

// x > 0 and finite: x = 0.DIGITS * 10^point; the number of digits (at most 17).
extern "C" size_t tm__shortest(double x, char *digits, int *point)
{
    char buf[32];  // d.dddddddddddddddde-308
    std::to_chars_result r =
        std::to_chars(buf, buf + sizeof buf - 1, x, std::chars_format::scientific);
    *r.ptr = '\0';
    size_t n = 0;
    const char *p = buf;
    digits[n++] = *p++;
    if (*p == '.')
        for (p++; *p != 'e'; p++)
            digits[n++] = *p;
    *point = std::atoi(p + 1) + 1;
    return n;
}
