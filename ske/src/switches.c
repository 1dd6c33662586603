/* SPDX-License-Identifier: Apache-2.0 */
/* Test switches (ima-ske --test-switch): deliberate breaches of what the SKE otherwise
 * guarantees, used only to show that a fault campaign's oracles notice them, and
 * every-quantum, the lockstep's plainer way, to show that the windows run ahead of the bus
 * change nothing. Each is recorded at module start; none is for a flight. */
#include "ske__supervisor.h"

#include <stdio.h>
#include <string.h>

static int bad(char *err, size_t errlen, const char *given, const char *why)
{
    snprintf(err, errlen, "--test-switch '%s': %s", given, why);
    return SKE_E_CONFIG;
}

/* "PARTITION" or "PARTITION.PORT": the partition's index (and the port's), or -1. */
static int find_partition(const ske_module_cfg_t *m, const char *name, size_t len)
{
    for (int i = 0; i < m->n_partitions; i++)
        if (strlen(m->partitions[i].name) == len && !strncmp(m->partitions[i].name, name, len))
            return i;
    return -1;
}

int ske__switches_parse(ske_switches_t *sw, const ske_module_cfg_t *m, const char *const *given,
                        int n, char *err, size_t errlen)
{
    memset(sw, 0, sizeof *sw);
    memset(sw->hm_action, -1, sizeof sw->hm_action);
    for (int i = 0; i < n; i++) {
        const char *g = given[i];
        if (sw->n == SKE_MAX_SWITCHES)
            return bad(err, errlen, g, "too many test switches");
        sw->given[sw->n++] = g;
        const char *eq = strchr(g, '=');
        size_t nlen = eq ? (size_t)(eq - g) : strlen(g);
        const char *v = eq ? eq + 1 : NULL;
        if (nlen == strlen("overrun-eats-next-window") && !strncmp(g, "overrun-eats-next-window", nlen)) {
            if (v)
                return bad(err, errlen, g, "overrun-eats-next-window takes no value");
            sw->eat_next_window = true;
        } else if (nlen == strlen("every-quantum") && !strncmp(g, "every-quantum", nlen)) {
            if (v)
                return bad(err, errlen, g, "every-quantum takes no value");
            sw->every_quantum = true;
        } else if (nlen == strlen("hm-action") && !strncmp(g, "hm-action", nlen)) {
            const char *colon = v ? strchr(v, ':') : NULL;
            if (!colon)
                return bad(err, errlen, g, "hm-action=PARTITION:ACTION");
            int pi = find_partition(m, v, (size_t)(colon - v));
            if (pi < 0)
                return bad(err, errlen, g, "unknown partition");
            hm_action_t a;
            if (!hm_action_parse(colon + 1, &a) ||
                (a != HM_ACT_IGNORE && a != HM_ACT_IDLE && a != HM_ACT_WARM_START && a != HM_ACT_COLD_START))
                return bad(err, errlen, g, "ACTION is a partition action: IGNORE, IDLE, WARM_START, COLD_START");
            sw->hm_action[pi] = (int8_t)a;
        } else if (nlen == strlen("corrupt-port") && !strncmp(g, "corrupt-port", nlen)) {
            const char *dot = v ? strchr(v, '.') : NULL;
            const char *at = dot ? strchr(dot, '@') : NULL;
            if (!at)
                return bad(err, errlen, g, "corrupt-port=PARTITION.PORT@TIME");
            ske_corrupt_switch_t *c = &sw->corrupt[sw->n_corrupt];
            c->partition = find_partition(m, v, (size_t)(dot - v));
            if (c->partition < 0)
                return bad(err, errlen, g, "unknown partition");
            const ske_partition_cfg_t *p = &m->partitions[c->partition];
            c->port = -1;
            for (int k = 0; k < p->n_ports; k++)
                if (strlen(p->ports[k].name) == (size_t)(at - dot - 1) &&
                    !strncmp(p->ports[k].name, dot + 1, (size_t)(at - dot - 1)))
                    c->port = k;
            if (c->port < 0)
                return bad(err, errlen, g, "the partition has no such port");
            if (p->ports[c->port].kind != SKE_PORT_SAMPLING || p->ports[c->port].dir != SKE_DIR_SOURCE)
                return bad(err, errlen, g, "not a source sampling port");
            if (fi_parse_time(at + 1, &c->t_ns) != 0)
                return bad(err, errlen, g, "bad TIME (a number with its unit: 120ms, 2s)");
            sw->n_corrupt++;
        } else {
            return bad(err, errlen, g, "unknown test switch (overrun-eats-next-window, "
                       "every-quantum, hm-action=PARTITION:ACTION, "
                       "corrupt-port=PARTITION.PORT@TIME)");
        }
    }
    return SKE_OK;
}

void ske__switches_trace(ske_t *s)
{
    for (int i = 0; i < s->sw.n; i++) {
        const char *g = s->sw.given[i];
        const char *eq = strchr(g, '=');
        ske_trace_begin(&s->trace, 0, "ske", "test_switch");
        ske_trace_strn(&s->trace, "name", g, eq ? (size_t)(eq - g) : strlen(g));
        if (eq)
            ske_trace_str(&s->trace, "value", eq + 1);
        ske_trace_end(&s->trace);
    }
}

/* corrupt-port: between windows, when no partition runs, the bytes of the port's latest
 * message are flipped in place; its sequence number and time stamp stay, so that it looks
 * like the message its writer wrote. */
void ske__switches_window_start(ske_t *s, int64_t t)
{
    for (int i = 0; i < s->sw.n_corrupt; i++) {
        ske_corrupt_switch_t *c = &s->sw.corrupt[i];
        if (c->done || t < c->t_ns)
            continue;
        c->done = true;
        ske_part_t *p = &s->parts[c->partition];
        uint32_t len, seq;
        uint8_t *msg = ske_sampling_latest_msg(p->ports[c->port].mem,
                                               p->cfg->ports[c->port].max_size, &len, &seq);
        for (uint32_t b = 0; msg && b < len; b++)
            msg[b] ^= 0xFFu;
    }
}

bool ske__switch_hm_action(const ske_t *s, const ske_part_t *p, hm_action_t *action)
{
    if (s->sw.hm_action[p->index] < 0)
        return false;
    *action = (hm_action_t)s->sw.hm_action[p->index];
    return true;
}
