/* SPDX-License-Identifier: Apache-2.0 */
/* The bus's trace (JSON lines, the same bytes for the same inputs) and its messages on
 * stderr. */
#include "canbus__server.h"

#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

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

/* ,"fid":ID of the fault that caused an event (nothing for none). */
static void sb_fid(canbus_bus_t *b, canbus_sbuf_t *s, uint16_t fault)
{
    if (!fault || fault > b->wire.n_faults)
        return;
    canbus_sb_str(s, ",\"fid\":");
    canbus_sb_json_str(s, b->wire.faults[fault - 1].fid, CANBUS_FID_MAX);
}

/* A client's name as plain text, for a fault's detail. */
static const char *plain_name(const canbus_bus_t *b, uint8_t index)
{
    if (index < CANBUS_WIRE_MAX_CLIENTS && b->by_index[index])
        return b->by_index[index]->name;
    return index == CANBUS_ANY ? "the bus" : "?";
}

/* What a fault's target is called: its client's name, the name it waits for, "any", or
 * "bus" for the bus's own babbler. */
static const char *target_name(const canbus_bus_t *b, size_t i)
{
    const canbus_fault_t *f = &b->wire.faults[i];
    if (f->target < CANBUS_WIRE_MAX_CLIENTS && b->by_index[f->target])
        return b->by_index[f->target]->name;
    if (f->target == CANBUS_NOBODY && i < b->o.n_faults)
        return b->o.faults[i].target_name;
    if (f->target == CANBUS_ANY)
        return f->kind == CANBUS_FAULT_BABBLE ? "bus" : "any";
    return "?";
}

static const char *const fault_states[] = {"?", "applied", "cleared", "refused"};

void canbus__sb_fault(canbus_bus_t *b, canbus_sbuf_t *s, int64_t t_ns, size_t i, uint8_t state,
                      const char *detail)
{
    const canbus_fault_t *f = &b->wire.faults[i];
    canbus__line_head(s, t_ns, "fault");
    canbus_sb_str(s, ",\"fid\":");
    canbus_sb_json_str(s, f->fid, CANBUS_FID_MAX);
    canbus_sb_str(s, ",\"class\":\"");
    canbus_sb_str(s, canbus_fault_class_name(f->kind));
    canbus_sb_str(s, "\",\"target\":");
    const char *target = target_name(b, i);
    canbus_sb_json_str(s, target, strlen(target));
    canbus_sb_str(s, ",\"state\":\"");
    canbus_sb_str(s, fault_states[state <= CANBUS_FAULT_REFUSED ? state : 0]);
    canbus_sb_str(s, "\",\"detail\":");
    canbus_sb_json_str(s, detail, strlen(detail));
    canbus_sb_str(s, "}\n");
}

/* A fault event of the wire: what the fault did first in its spell, or how its spell ended. */
static void trace_fault_event(canbus_bus_t *b, const canbus_wire_ev_t *e)
{
    size_t i = (size_t)e->fault - 1;
    const canbus_fault_t *f = &b->wire.faults[i];
    char detail[160];
    const char *from = plain_name(b, e->client);
    if (e->reason == CANBUS_FAULT_CLEARED) {
        uint32_t n = (uint32_t)e->data[0] | (uint32_t)e->data[1] << 8 |
                     (uint32_t)e->data[2] << 16 | (uint32_t)e->data[3] << 24;
        snprintf(detail, sizeof detail, "spell ended after %" PRIu32 " %s", n,
                 f->kind == CANBUS_FAULT_BUS_OFF ? "bus-off(s)" : "frame(s)");
    } else {
        switch (f->kind) {
        case CANBUS_FAULT_DROP:
            snprintf(detail, sizeof detail, "dropped 0x%" PRIX32 " from %s", e->id, from);
            break;
        case CANBUS_FAULT_CORRUPT:
            snprintf(detail, sizeof detail, "corrupted 0x%" PRIX32 " from %s", e->id, from);
            break;
        case CANBUS_FAULT_DELAY:
            snprintf(detail, sizeof detail, "delayed 0x%" PRIX32 " from %s by %" PRId64 " ns",
                     e->id, from, f->delay_ns);
            break;
        case CANBUS_FAULT_BABBLE:
            snprintf(detail, sizeof detail, "%s babbles 0x%" PRIX32, from, e->id);
            break;
        case CANBUS_FAULT_BUS_OFF: snprintf(detail, sizeof detail, "forced bus-off"); break;
        case CANBUS_FAULT_DUPLICATE:
            snprintf(detail, sizeof detail, "duplicated 0x%" PRIX32 " from %s", e->id, from);
            break;
        case CANBUS_FAULT_CUT:
            snprintf(detail, sizeof detail, "first frame cut: 0x%" PRIX32 " from %s", e->id,
                     from);
            break;
        default:
            snprintf(detail, sizeof detail, "0x%" PRIX32 " from %s not delivered", e->id, from);
            break;
        }
    }
    canbus__sb_fault(b, &b->line, e->end_ns, i, e->reason, detail);
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
        if (e->reason == CANBUS_TX_DUPLICATE)
            canbus_sb_str(s, ",\"duplicate\":true");
        sb_fid(b, s, e->fault);
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
        sb_fid(b, s, e->fault);
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
        sb_fid(b, s, e->fault);
        break;
    case CANBUS_EV_RX_DROP:
        canbus__line_head(s, e->end_ns, "can_rx_drop");
        canbus_sb_str(s, ",\"start_ns\":");
        canbus_sb_i64(s, e->start_ns);
        sb_frame(s, e);
        canbus__sb_client(b, s, "from", e->client);
        canbus_sb_str(s, ",\"to\":");
        if (e->to < CANBUS_WIRE_MAX_CLIENTS && b->by_index[e->to])
            canbus_sb_mem(s, b->by_index[e->to]->jname.p, b->by_index[e->to]->jname.n);
        else
            canbus_sb_str(s, "\"any\"");
        canbus_sb_str(s, ",\"to_client\":");
        canbus_sb_u64(s, e->to);
        sb_fid(b, s, e->fault);
        break;
    case CANBUS_EV_FAULT:
        trace_fault_event(b, e);
        canbus__trace_write(b, s);
        return;
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
