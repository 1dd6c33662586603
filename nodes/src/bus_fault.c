/* SPDX-License-Identifier: Apache-2.0 */
/* Bus faults from the command line ("kind:key=value,...") and from FAULT records. */
#include "canbus__wire.h"

#include <errno.h>
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const kind_names[] = {NULL, "drop", "corrupt", "delay", "babble", "bus_off"};

const char *canbus_fault_kind_name(uint8_t kind)
{
    return kind >= 1 && kind <= 5 ? kind_names[kind] : "unknown";
}

static void fault_defaults(canbus_fault_t *f, uint8_t kind)
{
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->target = CANBUS_ANY;
    f->match_id = CANBUS_ANY_ID;
    f->until_ns = INT64_MAX;
}

/* "123" (ns), "5us", "20ms", "1.5s". */
static int parse_time(const char *s, int64_t *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || errno || v < 0)
        return -1;
    double mul = 1;
    if (strcmp(end, "") == 0 || strcmp(end, "ns") == 0)
        mul = 1;
    else if (strcmp(end, "us") == 0)
        mul = 1e3;
    else if (strcmp(end, "ms") == 0)
        mul = 1e6;
    else if (strcmp(end, "s") == 0)
        mul = 1e9;
    else
        return -1;
    double ns = v * mul;
    if (ns > 9.2e18)
        return -1;
    *out = (int64_t)(ns + 0.5);
    return 0;
}

static int parse_u32(const char *s, uint32_t max, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 0);
    if (end == s || *end || errno || v > max)
        return -1;
    *out = (uint32_t)v;
    return 0;
}

int canbus_fault_parse(const char *spec, canbus_fault_t *f, char *target_name,
                       size_t name_size, char *err, size_t err_size)
{
    char buf[512];
    if (strlen(spec) >= sizeof buf) {
        snprintf(err, err_size, "fault spec too long");
        return CANBUS_WIRE_EINVAL;
    }
    strcpy(buf, spec);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = '\0';
    uint8_t kind = 0;
    for (uint8_t k = 1; k <= 5; k++)
        if (strcmp(buf, kind_names[k]) == 0)
            kind = k;
    if (!kind) {
        snprintf(err, err_size, "unknown fault kind '%s' (drop, corrupt, delay, babble, bus_off)",
                 buf);
        return CANBUS_WIRE_EINVAL;
    }
    fault_defaults(f, kind);
    target_name[0] = '\0';
    bool have_delay = false, ext = false;
    char *save = NULL;
    for (char *kv = colon ? strtok_r(colon + 1, ",", &save) : NULL; kv;
         kv = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(kv, '=');
        if (!eq) {
            snprintf(err, err_size, "'%s': expected key=value", kv);
            return CANBUS_WIRE_EINVAL;
        }
        *eq = '\0';
        const char *key = kv, *val = eq + 1;
        uint32_t u;
        int rc = 0;
        if (strcmp(key, "client") == 0) {
            if (strcmp(val, "any") == 0)
                f->target = CANBUS_ANY;
            else if (parse_u32(val, CANBUS_WIRE_MAX_CLIENTS - 1, &u) == 0)
                f->target = (uint8_t)u;
            else if (*val && strlen(val) < name_size && strlen(val) < CANBUS_NAME_LEN) {
                snprintf(target_name, name_size, "%s", val);
                f->target = CANBUS_NOBODY; /* bound when a client of that name joins */
            } else
                rc = -1;
        } else if (strcmp(key, "id") == 0) {
            if (strcmp(val, "any") == 0)
                f->match_id = CANBUS_ANY_ID;
            else if ((rc = parse_u32(val, 0x1FFFFFFF, &u)) == 0) {
                f->match_id = u;
                f->babble_id = u;
            }
        } else if (strcmp(key, "ext") == 0) {
            rc = parse_u32(val, 1, &u);
            ext = u == 1;
        } else if (strcmp(key, "len") == 0) {
            rc = parse_u32(val, 8, &u);
            f->babble_len = (uint8_t)u;
        } else if (strcmp(key, "from") == 0) {
            rc = parse_time(val, &f->from_ns);
        } else if (strcmp(key, "until") == 0) {
            rc = parse_time(val, &f->until_ns);
        } else if (strcmp(key, "count") == 0) {
            rc = parse_u32(val, 65535, &f->limit);
        } else if (strcmp(key, "delay") == 0) {
            rc = parse_time(val, &f->delay_ns);
            have_delay = rc == 0 && f->delay_ns > 0;
        } else if (strcmp(key, "recover") == 0) {
            rc = parse_u32(val, 1, &u);
            f->recover = u == 1;
        } else {
            snprintf(err, err_size, "unknown fault key '%s'", key);
            return CANBUS_WIRE_EINVAL;
        }
        if (rc) {
            snprintf(err, err_size, "bad value '%s' for '%s'", val, key);
            return CANBUS_WIRE_EINVAL;
        }
    }
    if (kind == CANBUS_FAULT_DELAY && !have_delay) {
        snprintf(err, err_size, "delay fault needs delay=TIME (> 0)");
        return CANBUS_WIRE_EINVAL;
    }
    if (kind == CANBUS_FAULT_BABBLE) {
        if (f->match_id == CANBUS_ANY_ID) {
            snprintf(err, err_size, "babble fault needs id=IDENTIFIER");
            return CANBUS_WIRE_EINVAL;
        }
        if (ext || f->babble_id > 0x7FF)
            f->babble_flags = CANBUS_FRAME_EFF;
        f->match_id = CANBUS_ANY_ID;
    }
    if (f->until_ns <= f->from_ns) {
        snprintf(err, err_size, "empty window: until must be after from");
        return CANBUS_WIRE_EINVAL;
    }
    return 0;
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int canbus_fault_from_rec(const struct canbus_rec *r, canbus_fault_t *f)
{
    if (r->type != CANBUS_MSG_FAULT || r->flags < 1 || r->flags > 5)
        return CANBUS_WIRE_EINVAL;
    fault_defaults(f, r->flags);
    if (r->data[0] != CANBUS_ANY && r->data[0] >= CANBUS_WIRE_MAX_CLIENTS)
        return CANBUS_WIRE_EINVAL;
    f->target = r->data[0];
    f->match_id = r->id;
    if (f->match_id != CANBUS_ANY_ID && f->match_id > 0x1FFFFFFF)
        return CANBUS_WIRE_EINVAL;
    f->from_ns = r->t_ns < 0 ? 0 : r->t_ns;
    f->until_ns = r->aux <= 0 ? INT64_MAX : r->aux;
    if (f->until_ns <= f->from_ns)
        return CANBUS_WIRE_EINVAL;
    switch (f->kind) {
    case CANBUS_FAULT_DROP:
    case CANBUS_FAULT_CORRUPT: f->limit = (uint32_t)r->data[1] | (uint32_t)r->data[2] << 8; break;
    case CANBUS_FAULT_DELAY:
        f->delay_ns = (int64_t)le32(&r->data[1]) * 1000;
        if (f->delay_ns <= 0)
            return CANBUS_WIRE_EINVAL;
        break;
    case CANBUS_FAULT_BABBLE: {
        uint32_t raw = le32(&r->data[1]);
        f->babble_id = raw & 0x1FFFFFFFu;
        f->babble_flags = (raw & 0x80000000u) ? CANBUS_FRAME_EFF : 0;
        if (!f->babble_flags && f->babble_id > 0x7FF)
            return CANBUS_WIRE_EINVAL;
        if (r->data[5] > 8)
            return CANBUS_WIRE_EINVAL;
        f->babble_len = r->data[5];
        f->limit = (uint32_t)r->data[6] | (uint32_t)r->data[7] << 8;
        f->match_id = CANBUS_ANY_ID;
        break;
    }
    case CANBUS_FAULT_BUS_OFF: f->recover = r->data[1] & 1; break;
    default: return CANBUS_WIRE_EINVAL;
    }
    return 0;
}
