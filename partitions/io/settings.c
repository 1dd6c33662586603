/* SPDX-License-Identifier: Apache-2.0 */
/* io's settings from its arguments: what differs from node to node and what the system model
 * says of voting and membership, written into the node's module by `ima deploy`. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_core.h"

/* The ranges io clamps each axis to before encoding it (the DBC's). */
const fi_wo_axis_t io_axes[IO_AXES] = {{"elev", -1, 1}, {"ail", -1, 1}, {"rud", -1, 1}, {"thr", 0, 1}};

const char *io_axis_name(int axis) { return axis >= 0 && axis < IO_AXES ? io_axes[axis].name : "?"; }

static int bad(char *err, size_t errlen, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int bad(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return -1;
}

/* A whole decimal number in [lo, hi]. */
static bool parse_uint(const char *text, unsigned lo, unsigned hi, unsigned *out)
{
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end || errno || v < (long)lo || v > (long)hi)
        return false;
    *out = (unsigned)v;
    return true;
}

/* The indices of the system's nodes, "1,2,3": a mask of their channels (bit k: index k+1). */
static bool parse_nodes(const char *text, uint32_t *mask)
{
    *mask = 0;
    for (const char *p = text;; p++) {
        if (*p < '1' || *p > '0' + XCH_MAX_NODES || (*mask & (1u << (*p - '1'))))
            return false;
        *mask |= 1u << (*p - '1');
        if (!p[1])
            return true;
        if (*++p != ',')
            return false;
    }
}

/* A finite number. */
static bool parse_double(const char *text, char **end, double *out)
{
    errno = 0;
    double v = strtod(text, end);
    if (*end == text || errno || !isfinite(v))
        return false;
    *out = v;
    return true;
}

static bool copy_text(char *dst, size_t size, const char *text)
{
    size_t n = strlen(text);
    if (n == 0 || n >= size)
        return false;
    memcpy(dst, text, n + 1);
    return true;
}

static bool parse_thresholds(const char *text, double out[IO_AXES])
{
    const char *p = text;
    for (int i = 0; i < IO_AXES; i++) {
        char *end;
        if (!parse_double(p, &end, &out[i]) || out[i] < 0)
            return false;
        if (i < IO_AXES - 1 && *end != ',')
            return false;
        p = end + (i < IO_AXES - 1);
        if (i == IO_AXES - 1 && *end)
            return false;
    }
    return true;
}

/* One --fault: a wrong_output fault with a fault id of its own. */
static bool add_fault(const char *text, io_settings_t *s, char *why, size_t whylen)
{
    if (s->n_faults == IO_MAX_FAULTS) {
        snprintf(why, whylen, "more than %d faults", IO_MAX_FAULTS);
        return false;
    }
    fi_wo_t *f = &s->fault[s->n_faults];
    if (fi_wo_parse(text, io_axes, IO_AXES, f, why, whylen) != 0)
        return false;
    for (unsigned k = 0; k < s->n_faults; k++)
        if (!strcmp(s->fault[k].spec.fid, f->spec.fid)) {
            snprintf(why, whylen, "fault id %s given twice", f->spec.fid);
            return false;
        }
    s->n_faults++;
    return true;
}

/* --test-cmd-bias=AXIS=OFFSET@SECONDS: the older test switch, a permanent bias from SECONDS. */
static bool parse_bias(const char *text, io_settings_t *s, char *why, size_t whylen)
{
    const char *eq = strchr(text, '=');
    if (!eq)
        return false;
    char *end;
    double value, from;
    if (!parse_double(eq + 1, &end, &value) || *end != '@' || !parse_double(end + 1, &end, &from) ||
        *end || from < 0)
        return false;
    char spec[FI_SPEC_MAX];
    snprintf(spec, sizeof spec, "wrong_output:fid=test-cmd-bias,at=%.17gs,mode=bias,axis=%.*s,value=%.17g",
             from, (int)(eq - text), text, value);
    return add_fault(spec, s, why, whylen);
}

enum { OPT_NODE = 1, OPT_INDEX = 2, OPT_NODES = 4, OPT_CANBUS = 8, OPT_DDS = 16, OPT_THRESHOLDS = 32,
       OPT_PERSIST = 64, OPT_MISSES = 128, OPT_REQUIRED = 255 };

int io_settings_parse(io_settings_t *s, int argc, char *const argv[], char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    unsigned seen = 0, index = 0;
    char why[160] = "bad value";
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *eq = strchr(arg, '=');
        if (strncmp(arg, "--", 2) != 0 || !eq)
            return bad(err, errlen, "argument '%s' is not --NAME=VALUE", arg);
        size_t klen = (size_t)(eq - arg);
        const char *v = eq + 1;
#define IS(name) (klen == sizeof(name) - 1 && !strncmp(arg, name, klen))
        bool ok;
        unsigned bit;
        if (IS("--node"))
            bit = OPT_NODE, ok = copy_text(s->node, sizeof s->node, v);
        else if (IS("--node-index"))
            bit = OPT_INDEX, ok = parse_uint(v, 1, XCH_MAX_NODES, &index);
        else if (IS("--nodes"))
            bit = OPT_NODES, ok = parse_nodes(v, &s->node_mask);
        else if (IS("--canbus"))
            bit = OPT_CANBUS, ok = copy_text(s->canbus, sizeof s->canbus, v);
        else if (IS("--dds"))
            bit = OPT_DDS, ok = copy_text(s->dds, sizeof s->dds, v);
        else if (IS("--vote-thresholds"))
            bit = OPT_THRESHOLDS, ok = parse_thresholds(v, s->vote_threshold);
        else if (IS("--vote-persist"))
            bit = OPT_PERSIST, ok = parse_uint(v, 1, 1000, &s->vote_persist);
        else if (IS("--membership-missed-frames"))
            bit = OPT_MISSES, ok = parse_uint(v, 1, 1000, &s->membership_misses);
        else if (IS("--fault"))
            bit = 0, ok = add_fault(v, s, why, sizeof why);
        else if (IS("--test-cmd-bias"))
            bit = 0, ok = parse_bias(v, s, why, sizeof why);
        else
            return bad(err, errlen, "unknown argument '%.*s'", (int)klen, arg);
#undef IS
        if (!ok)
            return bad(err, errlen, "argument '%s': %s", arg, why);
        if (bit & seen)
            return bad(err, errlen, "argument '%.*s' given twice", (int)klen, arg);
        seen |= bit;
    }
    if ((seen & OPT_REQUIRED) != OPT_REQUIRED) {
        static const char *const names[] = {"--node", "--node-index", "--nodes", "--canbus", "--dds",
                                            "--vote-thresholds", "--vote-persist",
                                            "--membership-missed-frames"};
        for (unsigned b = 0; b < 8; b++)
            if (!(seen & (1u << b)))
                return bad(err, errlen, "argument %s is missing", names[b]);
    }
    if (!(s->node_mask & (1u << (index - 1))))
        return bad(err, errlen, "--node-index=%u is not one of --nodes", index);
    s->channel = index - 1;
    s->n_nodes = 0; /* channels 0 .. the highest node's */
    for (unsigned k = 0; k < XCH_MAX_NODES; k++)
        if (s->node_mask & (1u << k))
            s->n_nodes = k + 1;
    return 0;
}
