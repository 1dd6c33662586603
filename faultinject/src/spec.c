/* SPDX-License-Identifier: Apache-2.0 */
/* The fault spec every injector reads (fi/spec.h): parsing and the active spells in time. */
#include "fi/spec.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int bad(char *err, size_t errlen, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int bad(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

int fi_parse_time(const char *text, int64_t *ns)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || errno || !isfinite(v) || v < 0)
        return -1;
    double mul;
    if (!strcmp(end, "") || !strcmp(end, "ns"))
        mul = 1;
    else if (!strcmp(end, "us"))
        mul = 1e3;
    else if (!strcmp(end, "ms"))
        mul = 1e6;
    else if (!strcmp(end, "s"))
        mul = 1e9;
    else
        return -1;
    double t = v * mul;
    if (t >= 9.2e18)
        return -1;
    *ns = (int64_t)llround(t);
    return 0;
}

static bool id_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= FI_ID_MAX)
        return false;
    for (; *s; s++)
        if (!((*s >= 'A' && *s <= 'Z') || (*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') ||
              *s == '_' || *s == '-'))
            return false;
    return true;
}

static bool name_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= FI_NAME_MAX)
        return false;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '_'))
            return false;
    return true;
}

int fi_spec_parse(const char *text, fi_spec_t *out, char *err, size_t errlen)
{
    char buf[FI_SPEC_MAX];
    memset(out, 0, sizeof *out);
    out->until_ns = FI_NEVER;
    if (!text || strlen(text) >= sizeof buf)
        return bad(err, errlen, "fault spec missing or longer than %d characters", FI_SPEC_MAX - 1);
    strcpy(buf, text);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = '\0';
    if (!name_ok(buf))
        return bad(err, errlen, "'%s': a fault class is 1 to %d characters of a-z 0-9 _", buf,
                   FI_NAME_MAX - 1);
    strcpy(out->cls, buf);
    bool have_at = false, have_period = false, have_on = false;
    char *save = NULL;
    for (char *kv = colon ? strtok_r(colon + 1, ",", &save) : NULL; kv; kv = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(kv, '=');
        if (!eq)
            return bad(err, errlen, "'%s': expected KEY=VALUE", kv);
        *eq = '\0';
        const char *key = kv, *val = eq + 1;
        int rc = 0;
        if (!strcmp(key, "fid")) {
            if (!id_ok(val))
                return bad(err, errlen, "fid '%s': 1 to %d characters of A-Z a-z 0-9 _ -", val,
                           FI_ID_MAX - 1);
            strcpy(out->fid, val);
        } else if (!strcmp(key, "at") || !strcmp(key, "from")) {
            rc = fi_parse_time(val, &out->at_ns);
            have_at = true;
        } else if (!strcmp(key, "until")) {
            rc = fi_parse_time(val, &out->until_ns);
        } else if (!strcmp(key, "period")) {
            rc = fi_parse_time(val, &out->period_ns);
            have_period = true;
        } else if (!strcmp(key, "on")) {
            rc = fi_parse_time(val, &out->on_ns);
            have_on = true;
        } else {
            if (out->n_params == FI_MAX_PARAMS)
                return bad(err, errlen, "more than %d parameters", FI_MAX_PARAMS);
            if (strlen(key) == 0 || strlen(key) >= FI_KEY_MAX || strlen(val) >= FI_VALUE_MAX)
                return bad(err, errlen, "parameter '%s' too long or empty", key);
            if (fi_spec_param(out, key))
                return bad(err, errlen, "parameter '%s' given twice", key);
            strcpy(out->params[out->n_params].key, key);
            strcpy(out->params[out->n_params].value, val);
            out->n_params++;
            continue;
        }
        if (rc)
            return bad(err, errlen, "bad time '%s' for '%s'", val, key);
    }
    if (!out->fid[0])
        return bad(err, errlen, "%s: fid=ID is required", out->cls);
    if (!have_at)
        return bad(err, errlen, "%s: at=TIME is required", out->cls);
    if (out->until_ns != FI_NEVER && out->until_ns <= out->at_ns)
        return bad(err, errlen, "%s: until must be after at", out->cls);
    if (have_period != have_on)
        return bad(err, errlen, "%s: an intermittent fault has both period and on", out->cls);
    if (have_period) {
        if (out->period_ns <= 0 || out->on_ns <= 0 || out->on_ns > out->period_ns)
            return bad(err, errlen, "%s: needs 0 < on <= period", out->cls);
        out->duration = FI_INTERMITTENT;
    } else {
        out->duration = out->until_ns == FI_NEVER ? FI_PERMANENT : FI_TRANSIENT;
    }
    return 0;
}

const char *fi_spec_param(const fi_spec_t *s, const char *key)
{
    for (int i = 0; i < s->n_params; i++)
        if (!strcmp(s->params[i].key, key))
            return s->params[i].value;
    return NULL;
}

int fi_spec_double(const fi_spec_t *s, const char *key, double def, double *out)
{
    const char *v = fi_spec_param(s, key);
    if (!v) {
        *out = def;
        return 0;
    }
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    if (end == v || *end || errno || !isfinite(d))
        return -1;
    *out = d;
    return 0;
}

int fi_spec_time(const fi_spec_t *s, const char *key, int64_t def, int64_t *out)
{
    const char *v = fi_spec_param(s, key);
    if (!v) {
        *out = def;
        return 0;
    }
    return fi_parse_time(v, out);
}

int64_t fi_spec_spell(const fi_spec_t *s, int64_t t_ns)
{
    if (t_ns < s->at_ns || t_ns >= s->until_ns)
        return -1;
    if (s->duration != FI_INTERMITTENT)
        return 0;
    int64_t k = (t_ns - s->at_ns) / s->period_ns;
    return t_ns - (s->at_ns + k * s->period_ns) < s->on_ns ? k : -1;
}

int64_t fi_spec_spell_start(const fi_spec_t *s, int64_t k)
{
    return s->duration == FI_INTERMITTENT ? s->at_ns + k * s->period_ns : s->at_ns;
}

int64_t fi_spec_end(const fi_spec_t *s) { return s->until_ns; }

const char *fi_duration_name(fi_duration_t d)
{
    static const char *const names[] = {"permanent", "transient", "intermittent"};
    return (unsigned)d <= FI_INTERMITTENT ? names[d] : "?";
}
