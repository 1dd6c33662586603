/* SPDX-License-Identifier: Apache-2.0 */
/* The parts of trace_mcap.c in files of their own: reading a bus line (trace_mcap_json.c),
 * writing numbers as orjson does (trace_mcap_number.c) and the shortest digits of a double
 * (trace_mcap_digits.cc, C++17's std::to_chars). */
#ifndef TRACE_MCAP__PARTS_H
#define TRACE_MCAP__PARTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TM_MAX_DIGITS 18 /* decimal integers longer than this are the Python's to read */

typedef struct {
    const uint8_t *p;
    size_t n;
} span_t;

enum { V_NONE, V_STR, V_INT, V_TRUE, V_FALSE, V_NULL };

typedef struct {
    int type;
    span_t s;  /* a string's content, an integer's digits */
    bool neg;
} value_t;

/* The fields of a bus line the recording reads. */
typedef struct {
    value_t t_ns, kind, id, ext, rtr, data, from;
} can_line_t;

/* The fields a bus line has, read from its flat JSON object (the bus's own form: no white
 * space, every string plain); false for any other line. */
bool tm__read_can_line(const uint8_t *p, const uint8_t *end, can_line_t *l);
bool tm__eq(span_t s, const char *lit);
uint64_t tm__digits_value(span_t s);
int tm__hex_digit(uint8_t h);

/* A decimal integer into p (no NUL); its length. */
size_t tm__put_u64(char *p, uint64_t v);
size_t tm__put_i64(char *p, int64_t v);

/* The converter's output (trace_mcap.c), for the converters in files of their own
 * (trace_mcap_fdr.c): a call starts with tm__begin, adds messages (tm__message: the header and
 * index entry of a message of n data bytes, the data to go at the place returned; NULL when
 * out of memory) and ends with tm__end. */
#ifndef __cplusplus
#include "trace_mcap/trace_mcap.h"
void tm__begin(tm_conv_t *c, tm_result_t *r);
void tm__end(const tm_conv_t *c, tm_result_t *r);
uint8_t *tm__message(tm_conv_t *c, uint16_t cid, uint64_t seq, uint64_t t, uint64_t base,
                     size_t n);
int tm__kind(const tm_conv_t *c);
uint16_t tm__channel(const tm_conv_t *c, int which);
size_t tm__out_len(const tm_conv_t *c);
#endif

/* x > 0 and finite: x = 0.DIGITS * 10^point; returns the number of digits (1 to 17). */
size_t tm__shortest(double x, char *digits, int *point);

#ifdef __cplusplus
}
#endif

#endif
