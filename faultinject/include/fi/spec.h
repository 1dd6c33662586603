/* SPDX-License-Identifier: Apache-2.0 */
/* One fault as every injector of the product reads it from its command line:
 *
 *     CLASS:fid=ID,at=TIME[,until=TIME][,period=TIME,on=TIME][,KEY=VALUE...]
 *
 * CLASS names the fault class (faultinject/catalogue.yaml); `fid` the fault of the run it
 * belongs to (as the injector's `fault` trace events name it); `at` (alias `from`) when it
 * starts, emulated time. TIME is a number with a unit: ns (or none), us, ms, s.
 *
 * Its duration:
 *   permanent     no `until`, no `period`: active from `at` on. A fault that happens once
 *                 (a crash, a division by zero) happens again every time its target runs
 *                 again after a restart: the cause is still there.
 *   transient     `until`: active in [at, until). A fault that happens once happens once.
 *   intermittent  `period` and `on`: active in [at + k*period, at + k*period + on), up to
 *                 `until` if given. A fault that happens once happens once per active spell.
 *
 * Any other KEY=VALUE pair is the class's parameter, left to the injector. Pure C11: no
 * allocation, no I/O, no global state. */
#ifndef FI_SPEC_H
#define FI_SPEC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define FI_NAME_MAX 32   /* a class name, with its NUL */
#define FI_ID_MAX 16     /* a fault id, with its NUL */
#define FI_KEY_MAX 24
#define FI_VALUE_MAX 104
#define FI_MAX_PARAMS 12
#define FI_SPEC_MAX 1024 /* the longest spec accepted */
#define FI_NEVER INT64_MAX

typedef enum { FI_PERMANENT = 0, FI_TRANSIENT = 1, FI_INTERMITTENT = 2 } fi_duration_t;

typedef struct {
    char cls[FI_NAME_MAX];
    char fid[FI_ID_MAX];
    int64_t at_ns;
    int64_t until_ns;  /* FI_NEVER: none */
    int64_t period_ns; /* intermittent: > 0 */
    int64_t on_ns;     /* intermittent: 0 < on <= period */
    fi_duration_t duration;
    int n_params;
    struct {
        char key[FI_KEY_MAX];
        char value[FI_VALUE_MAX];
    } params[FI_MAX_PARAMS];
} fi_spec_t;

/* Parses `text`; 0, or -1 with one line in err saying what is wrong. A fault id is 1 to 15
 * characters of A-Z a-z 0-9 _ -; `fid` and `at` are required. */
int fi_spec_parse(const char *text, fi_spec_t *out, char *err, size_t errlen);

/* The value of parameter `key`, or NULL. */
const char *fi_spec_param(const fi_spec_t *s, const char *key);
/* A parameter as a number / a time; def when absent; -1 when present but not one. */
int fi_spec_double(const fi_spec_t *s, const char *key, double def, double *out);
int fi_spec_time(const fi_spec_t *s, const char *key, int64_t def, int64_t *out);

/* "123", "123ns", "5us", "20ms", "1.5s": 0 and *ns, or -1. */
int fi_parse_time(const char *text, int64_t *ns);

/* The active spell at time t: its number k >= 0 (always 0 for permanent and transient
 * faults), or -1 when the fault is not active at t. */
int64_t fi_spec_spell(const fi_spec_t *s, int64_t t_ns);
/* The start of spell k. */
int64_t fi_spec_spell_start(const fi_spec_t *s, int64_t k);
/* When the fault stops for good (FI_NEVER for a permanent or endless intermittent one). */
int64_t fi_spec_end(const fi_spec_t *s);

const char *fi_duration_name(fi_duration_t d); /* "permanent", "transient", "intermittent" */

#endif
