/* SPDX-License-Identifier: Apache-2.0 */
/* Sample sets for the SKE's measured figures (window switch, start jitter). */
#ifndef SKE__STATS_H
#define SKE__STATS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

typedef struct {
    int64_t *v;
    size_t n, cap, limit;
    uint64_t count; /* all samples, kept or not */
    int64_t max;
} ske_samples_t;

void ske_samples_init(ske_samples_t *s, size_t limit);
void ske_samples_add(ske_samples_t *s, int64_t x);
void ske_samples_free(ske_samples_t *s);
/* {"count":..,"median":..,"p99":..,"max":..} in microseconds, or null when empty. */
void ske_samples_json_us(ske_samples_t *s, FILE *f);
/* q in [0,1] on the kept samples, in the samples' unit; sorts in place. */
double ske_samples_quantile(ske_samples_t *s, double q);

#endif /* SKE__STATS_H */
