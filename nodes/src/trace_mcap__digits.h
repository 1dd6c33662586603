/* SPDX-License-Identifier: Apache-2.0 */
/* The shortest round-trip digits of a double (trace_mcap_digits.cc, C++17's std::to_chars). */
#ifndef TRACE_MCAP__DIGITS_H
#define TRACE_MCAP__DIGITS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* x > 0 and finite: x = 0.DIGITS * 10^point; returns the number of digits (1 to 17). */
size_t tm__shortest(double x, char *digits, int *point);

#ifdef __cplusplus
}
#endif

#endif
