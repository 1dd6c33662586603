/* SPDX-License-Identifier: Apache-2.0 */
/* Sample sets for the SKE's measured figures. */
#include "ske__stats.h"

#include <stdlib.h>

void ske_samples_init(ske_samples_t *s, size_t limit)
{
    *s = (ske_samples_t){.limit = limit};
}

void ske_samples_add(ske_samples_t *s, int64_t x)
{
    s->count++;
    if (x > s->max)
        s->max = x;
    if (s->n == s->cap) {
        if (s->cap >= s->limit)
            return; /* keep the first `limit` samples; count and max still see all */
        size_t cap = s->cap ? s->cap * 2 : 1024;
        if (cap > s->limit)
            cap = s->limit;
        int64_t *v = realloc(s->v, cap * sizeof *v);
        if (!v)
            return;
        s->v = v;
        s->cap = cap;
    }
    s->v[s->n++] = x;
}

void ske_samples_free(ske_samples_t *s)
{
    free(s->v);
    *s = (ske_samples_t){0};
}

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

double ske_samples_quantile(ske_samples_t *s, double q)
{
    if (!s->n)
        return 0.0;
    qsort(s->v, s->n, sizeof *s->v, cmp_i64);
    double pos = q * (double)(s->n - 1);
    size_t i = (size_t)pos;
    double frac = pos - (double)i;
    if (i + 1 < s->n)
        return (double)s->v[i] * (1.0 - frac) + (double)s->v[i + 1] * frac;
    return (double)s->v[i];
}

void ske_samples_json_us(ske_samples_t *s, FILE *f)
{
    if (!s->count) {
        fputs("null", f);
        return;
    }
    double med = ske_samples_quantile(s, 0.5), p99 = ske_samples_quantile(s, 0.99);
    fprintf(f, "{\"count\":%llu,\"median\":%.3f,\"p99\":%.3f,\"max\":%.3f}",
            (unsigned long long)s->count, med / 1000.0, p99 / 1000.0, (double)s->max / 1000.0);
}
