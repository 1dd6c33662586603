/* SPDX-License-Identifier: Apache-2.0 */
/* The bus's quantum loop (proto.h): deliver what ended by the quantum's start and TICK the
 * LOCKSTEP clients, wait for every DONE, read what they sent, run the wire through the
 * quantum; at the end, STOP to everyone. */
#include "canbus__server.h"

#include <errno.h>
#include <inttypes.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int pending_done(const canbus_bus_t *b)
{
    int n = 0;
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone && b->live[i]->member && !b->live[i]->done)
            n++;
    return n;
}

static bool ev_rec(const canbus_wire_ev_t *e, struct canbus_rec *r)
{
    memset(r, 0, sizeof *r);
    r->flags = e->flags;
    r->len = e->len;
    r->src = e->client;
    r->id = e->id;
    r->t_ns = e->end_ns;
    r->aux = e->start_ns;
    switch (e->kind) {
    case CANBUS_EV_TX:
        r->type = CANBUS_MSG_FRAME;
        memcpy(r->data, e->data, 8);
        return true;
    case CANBUS_EV_BUS_OFF:
        if (!e->reason)
            return false; /* the ERROR record of the last error frame said so already */
        /* fall through */
    case CANBUS_EV_ERROR:
    case CANBUS_EV_BUS_ON:
        r->type = CANBUS_MSG_ERROR;
        r->data[0] = e->client;
        r->data[1] = e->state;
        r->data[2] = e->kind == CANBUS_EV_ERROR;
        r->data[3] = (uint8_t)(e->tec & 0xFF);
        r->data[4] = (uint8_t)(e->tec >> 8);
        return true;
    default: return false;
    }
}

static int out_reserve(canbus_bus_t *b, size_t n)
{
    if (n <= b->out_cap)
        return 0;
    size_t cap = b->out_cap ? b->out_cap : 1024;
    while (cap < n)
        cap *= 2;
    struct canbus_rec *v = realloc(b->out, cap * sizeof *v);
    if (!v)
        return -ENOMEM;
    b->out = v;
    b->out_cap = cap;
    return 0;
}

/* Is the TX or ERROR event k kept from `client` by a fault (an RX_DROP event after it)? */
static bool rx_dropped(const canbus_wire_t *w, size_t k, int client)
{
    for (size_t j = k + 1; j < w->n_ev; j++) {
        const canbus_wire_ev_t *e = &w->ev[j];
        if (e->kind == CANBUS_EV_FAULT)
            continue; /* a fault's own event may come between */
        if (e->kind != CANBUS_EV_RX_DROP)
            return false;
        if (e->to == client || e->to == CANBUS_ANY)
            return true;
    }
    return false;
}

/* Quantum start: frames that ended at or before t to CAN clients, then TICK to members. The
 * clients that get no TICK are served first: a node's io partition must hold its frames
 * before its SKE, granted the quantum, can run the window that reads them. */
static int deliver(canbus_bus_t *b, int64_t t, bool tick)
{
    canbus_wire_t *w = &b->wire;
    size_t first = w->ev_head, last = first;
    while (last < w->n_ev && w->ev[last].end_ns <= t)
        last++;
    if (out_reserve(b, last - first + 1))
        return -ENOMEM;
    if (tick)
        for (size_t i = 0; i < b->n_live; i++) {
            canbus_client_t *c = b->live[i];
            if (!c->gone && c->index >= 0 && c->member_next) {
                c->member = true;
                c->member_next = false;
                c->need_ns = 0;
            }
            /* A member with nothing to do before the end of this quantum (its DONE said when
             * it next has work) is not granted it: it is done with it already. */
            if (!c->gone && c->index >= 0 && c->member) {
                c->skip = c->need_ns > 0 && b->t_next <= c->need_ns;
                c->done = c->skip;
                c->ticks_skipped += c->skip;
            }
        }
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < b->n_live; i++) {
            canbus_client_t *c = b->live[i];
            if (c->gone || c->index < 0)
                continue;
            bool ticked = c->member && tick && !c->skip;
            if (ticked != (pass == 1))
                continue;
            size_t n = 0;
            if (c->roles & CANBUS_ROLE_CAN) {
                bool own = c->roles & CANBUS_ROLE_OWN;
                for (size_t k = first; k < last; k++) {
                    const canbus_wire_ev_t *e = &w->ev[k];
                    if (e->kind == CANBUS_EV_TX && e->client == c->index && !own)
                        continue;
                    if ((e->kind == CANBUS_EV_TX || e->kind == CANBUS_EV_ERROR) &&
                        k + 1 < w->n_ev && rx_dropped(w, k, c->index))
                        continue;
                    if (ev_rec(e, &b->out[n])) {
                        if (e->kind == CANBUS_EV_TX)
                            c->rx++;
                        n++;
                    }
                }
            }
            if (ticked) {
                c->done = false;
                c->ticks++;
                b->out[n++] = (struct canbus_rec){.type = CANBUS_MSG_TICK, .t_ns = b->t_next,
                                                  .aux = t};
                if (b->o.realtime) /* data = the release lateness, ns, little-endian */
                    for (int j = 0; j < 8; j++)
                        b->out[n - 1].data[j] = (uint8_t)((uint64_t)b->release_late_ns >> (8 * j));
            }
            for (size_t k = 0; k < n && !c->gone; k += CANBUS_MAX_RECS) {
                size_t m = n - k < CANBUS_MAX_RECS ? n - k : CANBUS_MAX_RECS;
                canbus__client_send(b, c, &b->out[k], m * sizeof *b->out);
            }
        }
    }
    w->ev_head = last;
    return 0;
}

/* Waits while a client's output queue is over its limit: a LOCKSTEP client for as long as
 * it takes, any other until the send timeout disconnects it (canbus__service()). */
static void wait_queues(canbus_bus_t *b)
{
    for (;;) {
        bool over = false;
        for (size_t i = 0; i < b->n_live; i++)
            if (!b->live[i]->gone && canbus__queued(b->live[i]) > b->o.client_buffer)
                over = true;
        if (!over || b->stopping)
            return;
        canbus__service(b, 100000000);
    }
}

/* --kill-node, --hang-node: kills (or freezes) the processes of every client of the node and
 * drops them, at the start of the quantum b->t (all of them are waiting for it: nothing they
 * do is half done). */
static void apply_kills(canbus_bus_t *b)
{
    for (size_t k = 0; k < b->o.n_kills; k++) {
        canbus_kill_t *kill_req = &b->o.kills[k];
        if (kill_req->done || kill_req->t_ns > b->t)
            continue;
        kill_req->done = true;
        bool hang = kill_req->sig == SIGSTOP;
        canbus_sbuf_t *s = &b->line;
        canbus__line_head(s, b->t, hang ? "node_hang" : "node_kill");
        canbus_sb_str(s, hang ? ",\"hung_node\":" : ",\"killed_node\":");
        canbus_sb_u64(s, kill_req->node);
        canbus_sb_str(s, ",\"clients\":[");
        bool first = true;
        for (size_t i = 0; i < b->n_live; i++) {
            canbus_client_t *c = b->live[i];
            if (c->gone || c->index < 0 || c->node != kill_req->node)
                continue;
            if (c->pid > 0)
                kill(c->pid, kill_req->sig);
            if (!first)
                canbus_sb_str(s, ",");
            first = false;
            canbus_sb_json_str(s, c->name, sizeof c->name);
            canbus__client_leave(b, c, hang ? "node_hung" : "node_killed");
        }
        canbus_sb_str(s, "]}\n");
        canbus__trace_write(b, s);
        canbus__info(b, "node %u %s at t=%" PRId64 " ns", kill_req->node, hang ? "hung" : "killed",
                     b->t);
    }
}

/* A fault whose named target never joined did nothing: the trace says so, at the end. */
static void refuse_unbound(canbus_bus_t *b)
{
    for (size_t i = 0; i < b->o.n_faults && i < b->wire.n_faults; i++) {
        if (b->wire.faults[i].target != CANBUS_NOBODY)
            continue;
        char detail[96];
        snprintf(detail, sizeof detail, "no CAN client '%s' joined", b->o.faults[i].target_name);
        canbus__sb_fault(b, &b->line, b->t, i, CANBUS_FAULT_REFUSED, detail);
        canbus__trace_write(b, &b->line);
    }
}

int canbus_bus_run(canbus_bus_t *b)
{
    int rc = 0;
    canbus__info(b, "listening on %s, waiting for %d lockstep client(s)", b->o.socket_path,
                 b->o.lockstep_clients);
    while (!b->stopping && canbus__members_count(b) < b->o.lockstep_clients)
        canbus__service(b, -1);
    b->started = true;
    b->start_wall = b->epoch_wall = canbus__wall_ns();
    b->t = 0;
    int64_t end = b->o.end_ns < 0 ? INT64_MAX : b->o.end_ns;
    if (!b->stopping)
        canbus__info(b, "started");

    while (!b->stopping && b->t < end) {
        b->t_next = end - b->t > b->o.quantum_ns ? b->t + b->o.quantum_ns : end;
        if (b->o.realtime) {
            for (int64_t now; !b->stopping && (now = canbus__wall_ns()) < b->epoch_wall + b->t;)
                canbus__service(b, b->epoch_wall + b->t - now);
            /* How late this quantum goes out (the nodes took longer than the wall clock): the
             * TICK carries it, so a node can tell how late each of its windows starts. */
            b->release_late_ns = canbus__wall_ns() - (b->epoch_wall + b->t);
            if (b->release_late_ns > b->late_max_ns)
                b->late_max_ns = b->release_late_ns;
            b->quanta_late += b->release_late_ns > 1000000;
        } else if (b->o.pace > 0) {
            /* Paced: quantum T is released no earlier than T / pace after the start. */
            int64_t due = b->epoch_wall + (int64_t)((double)b->t / b->o.pace);
            for (int64_t now; !b->stopping && (now = canbus__wall_ns()) < due;)
                canbus__service(b, due - now);
        }
        wait_queues(b);
        if (b->stopping)
            break;
        apply_kills(b);
        canbus__flush_staged(b);
        if ((rc = deliver(b, b->t, true)))
            break;
        while (!b->stopping && pending_done(b) > 0)
            canbus__service(b, -1);
        if (b->stopping)
            break;
        canbus__read_all(b);
        canbus__flush_staged(b);
        if ((rc = canbus_wire_run(&b->wire, b->t_next)))
            break;
        canbus__write_wire_trace(b);
        b->t = b->t_next;
        b->quanta++;
    }
    if (!b->stopping && rc == 0) {
        b->stop_reason = CANBUS_STOP_END;
        rc = deliver(b, b->t, false);
    }
    b->end_wall = canbus__wall_ns();
    canbus__flush_staged(b);
    refuse_unbound(b);
    canbus__line_head(&b->line, b->t, "bus_stop");
    canbus_sb_str(&b->line, ",\"reason\":\"");
    canbus_sb_str(&b->line, canbus__stop_name(b->stop_reason));
    canbus_sb_str(&b->line, "\"}\n");
    canbus__trace_write(b, &b->line);
    canbus__info(b, "stopping at t=%" PRId64 " ns after %" PRIu64 " quanta, %" PRIu64 " frames",
                 b->t, b->quanta, b->wire.frames);

    /* STOP to everyone, then a bounded time for the queues to drain and the lockstep members
     * to leave. A node still in the quantum a stop came in (the world's crash, the
     * launcher's stop) finishes it into an open socket, never into a bus already gone: what
     * its partitions do there, and so its trace, does not depend on when the stop came. What
     * they send now is read and dropped. */
    if (b->listen_fd >= 0) {
        close(b->listen_fd);
        b->listen_fd = -1;
        unlink(b->o.socket_path);
    }
    for (size_t i = 0; i < b->n_live; i++)
        canbus__send_stop(b, b->live[i], b->stop_reason);
    int64_t deadline = canbus__wall_ns() + 2000000000;
    for (int64_t now; (now = canbus__wall_ns()) <= deadline;) {
        bool waiting = false;
        for (size_t i = 0; i < b->n_live; i++) {
            canbus_client_t *c = b->live[i];
            if (!c->gone)
                canbus__flush_queue(b, c);
            if (!c->gone && (canbus__queued(c) || c->member))
                waiting = true;
        }
        if (!waiting)
            break;
        canbus__service(b, deadline - now < 10000000 ? deadline - now : 10000000);
    }
    return rc;
}
