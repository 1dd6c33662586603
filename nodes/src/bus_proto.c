/* SPDX-License-Identifier: Apache-2.0 */
/* The bus's side of the protocol of proto.h: hellos (welcome or refusal), and the records of
 * welcomed clients (frames, DONE, STOP), each checked before it is acted on. Who may join and
 * send what is bus_admit.c's; faults come only over the launcher's channel (bus_control.c). */
#include "canbus__server.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

void canbus__reject(canbus_bus_t *b, canbus_client_t *c, const char *reason)
{
    c->rejected++;
    b->rejected++;
    canbus__staged_reject(b, c, reason);
    if (c->rejected > (uint64_t)b->o.max_rejects) {
        b->garbage_kicks++;
        canbus__client_leave(b, c, "garbage");
    }
}

int canbus__members_count(const canbus_bus_t *b)
{
    int n = 0;
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone && (b->live[i]->member || b->live[i]->member_next))
            n++;
    return n;
}

static int indexed_live(const canbus_bus_t *b)
{
    int n = 0;
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone && b->live[i]->index >= 0)
            n++;
    return n;
}

static void refuse(canbus_bus_t *b, canbus_client_t *c, uint32_t reason, const char *why)
{
    canbus__line_head(&b->staged, b->t, "reject");
    canbus_sb_str(&b->staged, ",\"name\":");
    canbus_sb_mem(&b->staged, c->jname.p, c->jname.n);
    canbus_sb_str(&b->staged, ",\"reason\":\"");
    canbus_sb_str(&b->staged, why);
    canbus_sb_str(&b->staged, "\"}\n");
    canbus__note_refused_hello(b, c, why);
    canbus__send_stop(b, c, reason);
    canbus__flush_queue(b, c);
    canbus__client_leave(b, c, why);
}

/* Does a fault's target name designate this client? Its own name, if it has the CAN role
 * (its controller is what faults act on); or a node's name, "node2", for that node's first
 * CAN client, "node2/io" (a node's SKE, "node2", has no CAN controller). */
static bool names(const char *target, const canbus_client_t *c)
{
    if (!(c->roles & CANBUS_ROLE_CAN))
        return false;
    size_t n = strlen(target);
    return strcmp(target, c->name) == 0 || (strncmp(target, c->name, n) == 0 && c->name[n] == '/');
}

/* Command-line faults that name this client are bound to its index. */
static void bind_faults(canbus_bus_t *b, const canbus_client_t *c)
{
    for (size_t i = 0; i < b->o.n_faults && i < b->wire.n_faults; i++) {
        canbus_fault_t *f = &b->wire.faults[i];
        if (f->target == CANBUS_NOBODY && b->o.faults[i].target_name[0] &&
            names(b->o.faults[i].target_name, c))
            f->target = (uint8_t)c->index;
    }
}

void canbus__handle_hello(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n)
{
    struct canbus_hello h;
    if (n != sizeof h) {
        canbus_sb_json_str(&c->jname, "", 0);
        b->bad_hellos++;
        refuse(b, c, CANBUS_STOP_BAD_HELLO, "bad_hello");
        return;
    }
    memcpy(&h, p, sizeof h);
    memcpy(c->name, h.name, CANBUS_NAME_LEN);
    c->name[CANBUS_NAME_LEN] = '\0';
    canbus_sb_json_str(&c->jname, c->name, CANBUS_NAME_LEN);
    if (h.magic != CANBUS_MAGIC || h.version != CANBUS_VERSION ||
        (h.roles & ~(CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP | CANBUS_ROLE_OWN))) {
        b->bad_hellos++;
        refuse(b, c, CANBUS_STOP_BAD_HELLO, "bad_hello");
        return;
    }
    uint32_t stop_reason;
    const char *why = canbus__admit(b, c, &h, &stop_reason);
    if (why) {
        if (stop_reason == CANBUS_STOP_BAD_HELLO)
            b->bad_hellos++;
        else
            b->refused_hellos++;
        refuse(b, c, stop_reason, why);
        return;
    }
    bool lockstep = h.roles & CANBUS_ROLE_LOCKSTEP;
    if (lockstep && b->started && canbus__members_count(b) >= b->o.lockstep_clients) {
        b->late_joins++;
        refuse(b, c, CANBUS_STOP_LATE_JOIN, "late_join");
        return;
    }
    if (indexed_live(b) >= b->o.max_clients || b->next_index >= CANBUS_WIRE_MAX_CLIENTS) {
        b->full++;
        refuse(b, c, CANBUS_STOP_FULL, "full");
        return;
    }
    c->index = -1;
    for (size_t k = 0; k < b->o.n_order; k++)
        if (!b->by_index[k] && strcmp(b->o.order[k], c->name) == 0) {
            c->index = (int)k; /* its place in --client-order */
            break;
        }
    if (c->index < 0)
        c->index = b->next_index++;
    c->roles = h.roles;
    c->node = h.node;
    b->by_index[c->index] = c;
    if (lockstep) {
        c->member = !b->started;
        c->member_next = b->started;
    }
    struct canbus_welcome wl = {
        .magic = CANBUS_MAGIC,
        .version = CANBUS_VERSION,
        .client = (uint16_t)c->index,
        .bitrate = b->o.bitrate,
        .flags = (b->o.realtime ? CANBUS_WELCOME_REALTIME : 0) |
                 (c->listen_only ? CANBUS_WELCOME_LISTEN_ONLY : 0),
        .quantum_ns = b->o.quantum_ns,
        .t_ns = !b->started ? 0 : c->member_next ? b->t_next : b->t,
        .end_ns = b->o.end_ns,
    };
    canbus__client_send(b, c, &wl, sizeof wl);
    if (c->roles & CANBUS_ROLE_CAN) {
        canbus_wire_attach(&b->wire, (uint8_t)c->index, true);
        canbus_wire_arm_recovery(&b->wire, (uint8_t)c->index, b->o.recover);
    }
    bind_faults(b, c);
    canbus_sbuf_t *s = &c->staged;
    canbus__line_head(s, wl.t_ns, "client_join");
    canbus__sb_client(b, s, "name", (uint8_t)c->index);
    canbus_sb_str(s, ",\"roles\":[");
    const char *sep = "";
    if (c->roles & CANBUS_ROLE_CAN) {
        canbus_sb_str(s, "\"can\"");
        sep = ",";
    }
    if (c->roles & CANBUS_ROLE_LOCKSTEP) {
        canbus_sb_str(s, sep);
        canbus_sb_str(s, "\"lockstep\"");
        sep = ",";
    }
    if (c->roles & CANBUS_ROLE_OWN) {
        canbus_sb_str(s, sep);
        canbus_sb_str(s, "\"own\"");
    }
    canbus_sb_str(s, "],\"node_id\":");
    canbus_sb_u64(s, c->node);
    if (c->listen_only)
        canbus_sb_str(s, ",\"listen_only\":true");
    canbus_sb_str(s, "}\n");
    canbus__info(b, "client %d (%s) joined, roles 0x%x", c->index, c->name, c->roles);
}

void canbus__handle_records(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n)
{
    for (size_t off = 0; off < n && !c->gone; off += sizeof(struct canbus_rec)) {
        struct canbus_rec r;
        memcpy(&r, p + off, sizeof r);
        if (c->listen_only) {
            canbus__refuse_record(b, c, r.type, "listen_only");
            continue;
        }
        switch (r.type) {
        case CANBUS_MSG_FRAME: {
            if (!(c->roles & CANBUS_ROLE_CAN)) {
                canbus__reject(b, c, "frame_without_can_role");
                break;
            }
            if (r.len > 8) {
                canbus__reject(b, c, "len");
                break;
            }
            if (r.flags & ~(CANBUS_FRAME_EFF | CANBUS_FRAME_RTR)) {
                canbus__reject(b, c, "flags");
                break;
            }
            if (r.id > ((r.flags & CANBUS_FRAME_EFF) ? 0x1FFFFFFFu : 0x7FFu)) {
                canbus__reject(b, c, "id");
                break;
            }
            /* proto.h: LOCKSTEP clients stamp their frames (not before the quantum they are
             * in); the bus stamps the others' with the current quantum's start. */
            int64_t req = b->t;
            if (c->roles & CANBUS_ROLE_LOCKSTEP) {
                if (r.t_ns < b->t)
                    c->clamped++;
                else
                    req = r.t_ns;
            }
            int rc = canbus_wire_submit(&b->wire, req, r.id, r.flags, r.len, r.data,
                                        (uint8_t)c->index);
            if (rc == CANBUS_WIRE_EFULL) {
                c->overflow++; /* its controller's queue is full, as ENOBUFS on SocketCAN */
                break;
            }
            if (rc) {
                canbus__reject(b, c, "out_of_memory");
                break;
            }
            c->tx++;
            break;
        }
        case CANBUS_MSG_DONE:
            if (!c->member || c->done || r.t_ns != b->t_next) {
                canbus__reject(b, c, "bad_done");
                break;
            }
            c->done = true;
            c->need_ns = r.aux; /* proto.h: the instant it next has work at, or 0 */
            break;
        case CANBUS_MSG_STOP: /* the world's after a crash; a tool's is not its to send */
            if (c->roles & CANBUS_ROLE_LOCKSTEP)
                canbus__stop_by(b, c);
            else
                canbus__refuse_record(b, c, r.type, "control_record");
            break;
        case CANBUS_MSG_FAULT: /* only the launcher arms faults and names processes, */
        case CANBUS_MSG_PROCESS: /* over its own channel */
            canbus__refuse_record(b, c, r.type, "control_record");
            break;
        default: canbus__reject(b, c, "type"); break;
        }
    }
}
