/* SPDX-License-Identifier: Apache-2.0 */
/* The bus's trace (JSON lines, the same bytes for the same inputs) and its messages on
 * stderr. */
#include "canbus__server.h"

#include <stdarg.h>
#include <stdio.h>

void canbus__info(const canbus_bus_t *b, const char *fmt, ...)
{
    if (b->o.quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    fputs("ima-canbus: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* Every line starts alike, as in every trace of a run: t_ns, node, src, kind
 * (docs/trace-format.md, "Other traces of a run"). */
void canbus__line_head(canbus_sbuf_t *s, int64_t t_ns, const char *kind)
{
    canbus_sb_str(s, "{\"t_ns\":");
    canbus_sb_i64(s, t_ns);
    canbus_sb_str(s, ",\"node\":\"canbus\",\"src\":\"canbus\",\"kind\":\"");
    canbus_sb_str(s, kind);
    canbus_sb_str(s, "\"");
}

void canbus__trace_write(canbus_bus_t *b, canbus_sbuf_t *s)
{
    if (b->trace && s->n && fwrite(s->p, 1, s->n, b->trace) != s->n)
        b->trace_error = true;
    s->n = 0;
}

const char *canbus__stop_name(uint32_t reason)
{
    return reason == CANBUS_STOP_END         ? "end"
           : reason == CANBUS_STOP_REQUESTED ? "requested"
                                             : "signal";
}

const char *canbus__state_name(unsigned st)
{
    return st == CANBUS_ERR_BUS_OFF ? "bus_off" : st == CANBUS_ERR_PASSIVE ? "passive" : "active";
}

void canbus__sb_client(canbus_bus_t *b, canbus_sbuf_t *s, const char *key, uint8_t index)
{
    canbus_sb_str(s, ",\"");
    canbus_sb_str(s, key);
    canbus_sb_str(s, "\":");
    if (index < CANBUS_WIRE_MAX_CLIENTS && b->by_index[index])
        canbus_sb_mem(s, b->by_index[index]->jname.p, b->by_index[index]->jname.n);
    else
        canbus_sb_str(s, index == CANBUS_ANY ? "\"babbler\"" : "\"?\"");
    canbus_sb_str(s, ",\"client\":");
    canbus_sb_u64(s, index);
}

static void sb_frame(canbus_sbuf_t *s, const canbus_wire_ev_t *e)
{
    canbus_sb_str(s, ",\"id\":");
    canbus_sb_u64(s, e->id);
    canbus_sb_str(s, (e->flags & CANBUS_FRAME_EFF) ? ",\"ext\":true" : ",\"ext\":false");
    if (e->flags & CANBUS_FRAME_RTR)
        canbus_sb_str(s, ",\"rtr\":true");
    canbus_sb_str(s, ",\"len\":");
    canbus_sb_u64(s, e->len);
}

static void trace_wire_event(canbus_bus_t *b, const canbus_wire_ev_t *e)
{
    canbus_sbuf_t *s = &b->line;
    switch (e->kind) {
    case CANBUS_EV_TX:
        canbus__line_head(s, e->end_ns, "can_tx");
        canbus_sb_str(s, ",\"start_ns\":");
        canbus_sb_i64(s, e->start_ns);
        sb_frame(s, e);
        canbus_sb_str(s, ",\"data\":\"");
        canbus_sb_hex(s, e->data, (e->flags & CANBUS_FRAME_RTR) ? 0 : e->len);
        canbus_sb_str(s, "\"");
        canbus__sb_client(b, s, "from", e->client);
        break;
    case CANBUS_EV_ERROR:
        canbus__line_head(s, e->end_ns, "can_error");
        canbus_sb_str(s, ",\"start_ns\":");
        canbus_sb_i64(s, e->start_ns);
        sb_frame(s, e);
        canbus__sb_client(b, s, "from", e->client);
        canbus_sb_str(s, ",\"tec\":");
        canbus_sb_u64(s, e->tec);
        canbus_sb_str(s, ",\"state\":\"");
        canbus_sb_str(s, canbus__state_name(e->state));
        canbus_sb_str(s, "\"");
        break;
    case CANBUS_EV_BUS_OFF:
    case CANBUS_EV_BUS_ON:
        canbus__line_head(s, e->end_ns, e->kind == CANBUS_EV_BUS_OFF ? "bus_off" : "bus_on");
        canbus__sb_client(b, s, "name", e->client);
        if (e->kind == CANBUS_EV_BUS_OFF)
            canbus_sb_str(s, e->reason ? ",\"cause\":\"fault\"" : ",\"cause\":\"errors\"");
        break;
    case CANBUS_EV_DROP:
        canbus__line_head(s, e->end_ns, "can_drop");
        sb_frame(s, e);
        canbus__sb_client(b, s, "from", e->client);
        canbus_sb_str(s, e->reason == CANBUS_DROP_BUS_OFF ? ",\"reason\":\"bus_off\""
                                                          : ",\"reason\":\"fault\"");
        break;
    default: return;
    }
    canbus_sb_str(s, "}\n");
    canbus__trace_write(b, s);
}

void canbus__staged_reject(canbus_bus_t *b, canbus_client_t *c, const char *reason)
{
    canbus_sbuf_t *s = &c->staged;
    canbus__line_head(s, b->t, "reject");
    if (c->index >= 0)
        canbus__sb_client(b, s, "name", (uint8_t)c->index);
    canbus_sb_str(s, ",\"reason\":\"");
    canbus_sb_str(s, reason);
    canbus_sb_str(s, "\"}\n");
}

/* Trace lines of the read phase go out in client order, whatever order the sockets were
 * read in, so that the trace does not depend on scheduling. */
void canbus__flush_staged(canbus_bus_t *b)
{
    canbus__trace_write(b, &b->staged);
    for (int i = 0; i < b->next_index; i++)
        if (b->by_index[i])
            canbus__trace_write(b, &b->by_index[i]->staged);
}

int canbus__write_wire_trace(canbus_bus_t *b)
{
    canbus_wire_t *w = &b->wire;
    for (; w->ev_mark < w->n_ev; w->ev_mark++)
        trace_wire_event(b, &w->ev[w->ev_mark]);
    return 0;
}
