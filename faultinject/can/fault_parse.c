/* SPDX-License-Identifier: Apache-2.0 */
/* Bus faults from the command line (the common grammar of fi/spec.h, and the bus's older
 * KIND:KEY=VALUE forms) and from FAULT records. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "canbus__fault.h"
#include "fi/spec.h"

static const char *const class_names[CANBUS_FAULT_KINDS + 1] = {
    NULL, "can_drop", "can_corrupt", "can_delay", "babbling_idiot", "can_bus_off",
    "can_duplicate", "transceiver_cut", "rx_drop"};
/* The older kind names, by kind. */
static const char *const legacy_names[CANBUS_FAULT_BUS_OFF + 1] = {NULL, "drop", "corrupt",
                                                                   "delay", "babble", "bus_off"};
/* A fault id the older forms get before the caller assigns the real one. */
#define NO_FID "__none__"

const char *canbus_fault_class_name(uint8_t kind)
{
    return kind >= 1 && kind <= CANBUS_FAULT_KINDS ? class_names[kind] : "unknown";
}

static void fault_defaults(canbus_fault_t *f, uint8_t kind)
{
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->target = CANBUS_ANY;
    f->match_id = CANBUS_ANY_ID;
    f->until_ns = INT64_MAX;
    f->spell = f->last_spell = f->forced_spell = -1;
}

static int parse_u32(const char *s, uint32_t max, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 0);
    if (end == s || *end || errno || v > max || *s == '-')
        return -1;
    *out = (uint32_t)v;
    return 0;
}

static int fail(char *err, size_t err_size, const char *what, const char *detail)
{
    snprintf(err, err_size, "%s%s", what, detail);
    return CANBUS_FAULT_EINVAL;
}

/* One KEY=VALUE parameter of a bus fault. */
static int parse_param(canbus_fault_t *f, const char *key, const char *val, bool *ext,
                       bool *have_delay, char *target_name, size_t name_size)
{
    uint32_t u;
    if (strcmp(key, "client") == 0) {
        if (strcmp(val, "any") == 0) {
            f->target = CANBUS_ANY;
        } else if (*val >= '0' && *val <= '9') {
            /* an index (a name never starts with a digit here) */
            if (parse_u32(val, CANBUS_FAULT_MAX_INDEX, &u))
                return -1;
            f->target = (uint8_t)u;
        } else if (*val && strlen(val) < name_size && strlen(val) <= CANBUS_NAME_LEN) {
            snprintf(target_name, name_size, "%s", val);
            f->target = CANBUS_NOBODY; /* bound when a client of that name joins */
        } else {
            return -1;
        }
        return 0;
    }
    if (strcmp(key, "id") == 0) {
        if (strcmp(val, "any") == 0) {
            f->match_id = CANBUS_ANY_ID;
            return 0;
        }
        if (parse_u32(val, 0x1FFFFFFF, &u))
            return -1;
        f->match_id = f->babble_id = u;
        return 0;
    }
    if (strcmp(key, "ext") == 0) {
        if (parse_u32(val, 1, &u))
            return -1;
        *ext = u == 1;
        return 0;
    }
    if (strcmp(key, "len") == 0) {
        if (parse_u32(val, 8, &u))
            return -1;
        f->babble_len = (uint8_t)u;
        return 0;
    }
    if (strcmp(key, "count") == 0)
        return parse_u32(val, 65535, &f->limit);
    if (strcmp(key, "delay") == 0) {
        if (fi_parse_time(val, &f->delay_ns))
            return -1;
        *have_delay = f->delay_ns > 0;
        return 0;
    }
    if (strcmp(key, "recover") == 0) {
        if (parse_u32(val, 1, &u))
            return -1;
        f->recover = u == 1;
        return 0;
    }
    return -2;
}

int canbus_fault_parse(const char *spec, canbus_fault_t *f, char *target_name,
                       size_t name_size, char *err, size_t err_size)
{
    char cls[FI_NAME_MAX + 1];
    size_t n = strcspn(spec, ":");
    if (n >= sizeof cls)
        return fail(err, err_size, "fault class too long: ", spec);
    memcpy(cls, spec, n);
    cls[n] = '\0';
    uint8_t kind = 0;
    bool legacy = false;
    for (uint8_t k = 1; k <= CANBUS_FAULT_KINDS; k++)
        if (strcmp(cls, class_names[k]) == 0)
            kind = k;
    for (uint8_t k = 1; !kind && k <= CANBUS_FAULT_BUS_OFF; k++)
        if (strcmp(cls, legacy_names[k]) == 0)
            kind = k, legacy = true;
    if (!kind)
        return fail(err, err_size, "unknown bus fault class: ", "can_drop, can_corrupt, "
                    "can_delay, can_duplicate, babbling_idiot, can_bus_off, transceiver_cut, "
                    "rx_drop (or drop, corrupt, delay, babble, bus_off)");
    /* The older forms need neither fid nor a start: both get a default the spec may
     * override (a key given twice keeps its last value). */
    char text[FI_SPEC_MAX];
    int len = legacy ? snprintf(text, sizeof text, "%s:fid=" NO_FID ",at=0%s%s", cls,
                                spec[n] ? "," : "", spec[n] ? spec + n + 1 : "")
                     : snprintf(text, sizeof text, "%s", spec);
    if (len < 0 || (size_t)len >= sizeof text)
        return fail(err, err_size, "fault spec too long", "");
    fi_spec_t s;
    if (fi_spec_parse(text, &s, err, err_size))
        return CANBUS_FAULT_EINVAL;
    fault_defaults(f, kind);
    target_name[0] = '\0';
    if (strcmp(s.fid, NO_FID) != 0)
        snprintf(f->fid, sizeof f->fid, "%s", s.fid);
    f->from_ns = s.at_ns;
    f->until_ns = s.until_ns;
    if (s.duration == FI_INTERMITTENT) {
        f->period_ns = s.period_ns;
        f->on_ns = s.on_ns;
    }
    bool ext = false, have_delay = false;
    for (int i = 0; i < s.n_params; i++) {
        int rc = parse_param(f, s.params[i].key, s.params[i].value, &ext, &have_delay,
                             target_name, name_size);
        if (rc == -2)
            return fail(err, err_size, "unknown fault key: ", s.params[i].key);
        if (rc) {
            snprintf(err, err_size, "bad value '%s' for '%s'", s.params[i].value,
                     s.params[i].key);
            return CANBUS_FAULT_EINVAL;
        }
    }
    if (kind == CANBUS_FAULT_DELAY && !have_delay)
        return fail(err, err_size, cls, " needs delay=TIME (> 0)");
    if (kind == CANBUS_FAULT_BABBLE) {
        if (f->match_id == CANBUS_ANY_ID)
            return fail(err, err_size, cls, " needs id=IDENTIFIER (the one it sends)");
        if (ext || f->babble_id > 0x7FF)
            f->babble_flags = CANBUS_FRAME_EFF;
        f->match_id = CANBUS_ANY_ID;
    }
    if (kind == CANBUS_FAULT_CUT && f->target == CANBUS_ANY)
        return fail(err, err_size, cls, " needs client=NAME|INDEX (one client's transceiver)");
    if (legacy && kind == CANBUS_FAULT_BUS_OFF) {
        /* The older form acts once, at its start, whatever its window. */
        f->until_ns = INT64_MAX;
        f->period_ns = f->on_ns = 0;
    }
    return 0;
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int canbus_fault_from_rec(const struct canbus_rec *r, canbus_fault_t *f)
{
    if (r->type != CANBUS_MSG_FAULT || r->flags < 1 || r->flags > CANBUS_FAULT_KINDS)
        return CANBUS_FAULT_EINVAL;
    fault_defaults(f, r->flags);
    if (r->data[0] != CANBUS_ANY && r->data[0] > CANBUS_FAULT_MAX_INDEX)
        return CANBUS_FAULT_EINVAL;
    f->target = r->data[0];
    f->match_id = r->id;
    if (f->match_id != CANBUS_ANY_ID && f->match_id > 0x1FFFFFFF)
        return CANBUS_FAULT_EINVAL;
    f->from_ns = r->t_ns < 0 ? 0 : r->t_ns;
    f->until_ns = r->aux <= 0 ? INT64_MAX : r->aux;
    if (f->until_ns <= f->from_ns)
        return CANBUS_FAULT_EINVAL;
    switch (f->kind) {
    case CANBUS_FAULT_DROP:
    case CANBUS_FAULT_CORRUPT:
    case CANBUS_FAULT_DUPLICATE:
    case CANBUS_FAULT_RX_DROP: f->limit = (uint32_t)r->data[1] | (uint32_t)r->data[2] << 8; break;
    case CANBUS_FAULT_DELAY:
        f->delay_ns = (int64_t)le32(&r->data[1]) * 1000;
        if (f->delay_ns <= 0)
            return CANBUS_FAULT_EINVAL;
        break;
    case CANBUS_FAULT_BABBLE: {
        uint32_t raw = le32(&r->data[1]);
        f->babble_id = raw & 0x1FFFFFFFu;
        f->babble_flags = (raw & 0x80000000u) ? CANBUS_FRAME_EFF : 0;
        if (!f->babble_flags && f->babble_id > 0x7FF)
            return CANBUS_FAULT_EINVAL;
        if (r->data[5] > 8)
            return CANBUS_FAULT_EINVAL;
        f->babble_len = r->data[5];
        f->limit = (uint32_t)r->data[6] | (uint32_t)r->data[7] << 8;
        f->match_id = CANBUS_ANY_ID;
        break;
    }
    case CANBUS_FAULT_BUS_OFF:
        f->recover = r->data[1] & 1;
        f->until_ns = INT64_MAX; /* acts once, at t_ns */
        break;
    case CANBUS_FAULT_CUT:
        if (f->target == CANBUS_ANY)
            return CANBUS_FAULT_EINVAL;
        f->match_id = CANBUS_ANY_ID;
        break;
    default: return CANBUS_FAULT_EINVAL;
    }
    return 0;
}
