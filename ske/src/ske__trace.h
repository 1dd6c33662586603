/* SPDX-License-Identifier: Apache-2.0 */
/* JSON-lines trace writer of the SKE: one event per line, fixed key order, no wall clock in
 * emulated mode, so that two runs of the same module give byte-identical files. */
#ifndef SKE__TRACE_H
#define SKE__TRACE_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

typedef struct {
    FILE *f;
    bool owned;
    char node[64];
    int64_t last_flush_mono_ns;
} ske_trace_t;

int ske_trace_open(ske_trace_t *t, const char *path, const char *node);
/* Flushes and closes; a negative errno if anything written was lost (disk full, ...). */
int ske_trace_close(ske_trace_t *t);
/* An event is begin, fields, end. All are no-ops when the trace is off. */
void ske_trace_begin(ske_trace_t *t, int64_t t_ns, const char *src, const char *kind);
void ske_trace_str(ske_trace_t *t, const char *key, const char *val);
void ske_trace_strn(ske_trace_t *t, const char *key, const char *val, size_t len);
void ske_trace_int(ske_trace_t *t, const char *key, int64_t v);
void ske_trace_bool(ske_trace_t *t, const char *key, bool v);
void ske_trace_raw(ske_trace_t *t, const char *key, const char *json);
void ske_trace_end(ske_trace_t *t);
/* Flushes if more than 50 ms of wall time passed since the last flush, so a killed run
 * loses at most that much. */
void ske_trace_maybe_flush(ske_trace_t *t, int64_t mono_ns);
/* JSON string escaping into a FILE. */
void ske_json_escape(FILE *f, const char *s, size_t len);

#endif /* SKE__TRACE_H */
