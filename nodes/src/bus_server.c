/* SPDX-License-Identifier: Apache-2.0 */
/* The ima-canbus process: connections, the quantum loop of proto.h, delivery, trace, stats. */
#include "canbus__bus.h"

#include <errno.h>
#include <inttypes.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#define RXBUF_SIZE (CANBUS_MAX_RECS * sizeof(struct canbus_rec) + 64)

volatile sig_atomic_t canbus_signalled;

static int64_t wall_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void info(const canbus_bus_t *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void info(const canbus_bus_t *b, const char *fmt, ...)
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

/* ---- trace ------------------------------------------------------------------------------ */

/* Every line starts alike (DESIGN.md §8). */
static void line_head(canbus_sbuf_t *s, int64_t t_ns, const char *kind)
{
    canbus_sb_str(s, "{\"t_ns\":");
    canbus_sb_i64(s, t_ns);
    canbus_sb_str(s, ",\"node\":\"canbus\",\"src\":\"canbus\",\"kind\":\"");
    canbus_sb_str(s, kind);
    canbus_sb_str(s, "\"");
}

static void trace_write(canbus_bus_t *b, canbus_sbuf_t *s)
{
    if (b->trace && s->n && fwrite(s->p, 1, s->n, b->trace) != s->n)
        b->trace_error = true;
    s->n = 0;
}

static const char *stop_name(uint32_t reason)
{
    return reason == CANBUS_STOP_END         ? "end"
           : reason == CANBUS_STOP_REQUESTED ? "requested"
                                             : "signal";
}

static const char *state_name(unsigned st)
{
    return st == CANBUS_ERR_BUS_OFF ? "bus_off" : st == CANBUS_ERR_PASSIVE ? "passive" : "active";
}

static void sb_client(canbus_bus_t *b, canbus_sbuf_t *s, const char *key, uint8_t index)
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
        line_head(s, e->end_ns, "can_tx");
        canbus_sb_str(s, ",\"start_ns\":");
        canbus_sb_i64(s, e->start_ns);
        sb_frame(s, e);
        canbus_sb_str(s, ",\"data\":\"");
        canbus_sb_hex(s, e->data, (e->flags & CANBUS_FRAME_RTR) ? 0 : e->len);
        canbus_sb_str(s, "\"");
        sb_client(b, s, "from", e->client);
        break;
    case CANBUS_EV_ERROR:
        line_head(s, e->end_ns, "can_error");
        canbus_sb_str(s, ",\"start_ns\":");
        canbus_sb_i64(s, e->start_ns);
        sb_frame(s, e);
        sb_client(b, s, "from", e->client);
        canbus_sb_str(s, ",\"tec\":");
        canbus_sb_u64(s, e->tec);
        canbus_sb_str(s, ",\"state\":\"");
        canbus_sb_str(s, state_name(e->state));
        canbus_sb_str(s, "\"");
        break;
    case CANBUS_EV_BUS_OFF:
    case CANBUS_EV_BUS_ON:
        line_head(s, e->end_ns, e->kind == CANBUS_EV_BUS_OFF ? "bus_off" : "bus_on");
        sb_client(b, s, "name", e->client);
        if (e->kind == CANBUS_EV_BUS_OFF)
            canbus_sb_str(s, e->reason ? ",\"cause\":\"fault\"" : ",\"cause\":\"errors\"");
        break;
    case CANBUS_EV_DROP:
        line_head(s, e->end_ns, "can_drop");
        sb_frame(s, e);
        sb_client(b, s, "from", e->client);
        canbus_sb_str(s, e->reason == CANBUS_DROP_BUS_OFF ? ",\"reason\":\"bus_off\""
                                                          : ",\"reason\":\"fault\"");
        break;
    default: return;
    }
    canbus_sb_str(s, "}\n");
    trace_write(b, s);
}

static void staged_reject(canbus_bus_t *b, canbus_client_t *c, const char *reason)
{
    canbus_sbuf_t *s = &c->staged;
    line_head(s, b->t, "reject");
    if (c->index >= 0)
        sb_client(b, s, "name", (uint8_t)c->index);
    canbus_sb_str(s, ",\"reason\":\"");
    canbus_sb_str(s, reason);
    canbus_sb_str(s, "\"}\n");
}

/* Trace lines of the read phase go out in client order, whatever order the sockets were
 * read in, so that the trace does not depend on scheduling. */
static void flush_staged(canbus_bus_t *b)
{
    trace_write(b, &b->staged);
    for (int i = 0; i < b->next_index; i++)
        if (b->by_index[i])
            trace_write(b, &b->by_index[i]->staged);
}

/* ---- sending ---------------------------------------------------------------------------- */

static void client_leave(canbus_bus_t *b, canbus_client_t *c, const char *reason)
{
    if (c->gone)
        return;
    c->gone = true;
    c->leave_reason = reason;
    if (c->fd >= 0)
        close(c->fd);
    c->fd = -1;
    c->member = c->member_next = false;
    free(c->q);
    c->q = NULL;
    c->q_head = c->q_len = c->q_cap = 0;
    if (c->index < 0)
        return;
    canbus_wire_attach(&b->wire, (uint8_t)c->index, false);
    canbus_sbuf_t *s = &c->staged;
    line_head(s, b->t, "client_leave");
    sb_client(b, s, "name", (uint8_t)c->index);
    canbus_sb_str(s, ",\"reason\":\"");
    canbus_sb_str(s, reason);
    canbus_sb_str(s, "\"}\n");
    info(b, "client %d (%s) left: %s", c->index, c->name, reason);
}

static int enqueue(canbus_client_t *c, const void *p, size_t n)
{
    if (c->q_head == c->q_len)
        c->q_head = c->q_len = 0;
    if (c->q_len + 4 + n > c->q_cap) {
        if (c->q_head) {
            memmove(c->q, c->q + c->q_head, c->q_len - c->q_head);
            c->q_len -= c->q_head;
            c->q_head = 0;
        }
        size_t cap = c->q_cap ? c->q_cap : 65536;
        while (cap < c->q_len + 4 + n)
            cap *= 2;
        if (cap != c->q_cap) {
            uint8_t *q = realloc(c->q, cap);
            if (!q)
                return -ENOMEM;
            c->q = q;
            c->q_cap = cap;
        }
    }
    uint32_t len = (uint32_t)n;
    memcpy(c->q + c->q_len, &len, 4);
    memcpy(c->q + c->q_len + 4, p, n);
    c->q_len += 4 + n;
    return 0;
}

static size_t queued(const canbus_client_t *c)
{
    return c->q_len - c->q_head;
}

static void flush_queue(canbus_bus_t *b, canbus_client_t *c)
{
    while (!c->gone && c->q_head < c->q_len) {
        uint32_t len;
        memcpy(&len, c->q + c->q_head, 4);
        ssize_t r = send(c->fd, c->q + c->q_head + 4, len, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (r < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK)
                return;
            if (errno == EINTR)
                continue;
            client_leave(b, c, "closed");
            return;
        }
        c->q_head += 4 + len;
        c->q_progress_wall = wall_ns();
    }
}

/* Sends one datagram, in order after what is queued; never blocks (the quantum loop waits
 * for clients whose queue is long, see wait_queues()). */
static void client_send(canbus_bus_t *b, canbus_client_t *c, const void *p, size_t n)
{
    if (c->gone)
        return;
    if (queued(c) == 0) {
        for (;;) {
            ssize_t r = send(c->fd, p, n, MSG_DONTWAIT | MSG_NOSIGNAL);
            if (r >= 0)
                return;
            if (errno == EINTR)
                continue;
            if (errno == EAGAIN || errno == EWOULDBLOCK)
                break;
            client_leave(b, c, "closed");
            return;
        }
        c->q_progress_wall = wall_ns();
    }
    if (enqueue(c, p, n))
        client_leave(b, c, "out_of_memory");
}

static void send_stop(canbus_bus_t *b, canbus_client_t *c, uint32_t reason)
{
    struct canbus_rec r = {.type = CANBUS_MSG_STOP, .id = reason, .t_ns = b->t};
    client_send(b, c, &r, sizeof r);
}

/* ---- receiving -------------------------------------------------------------------------- */

static void reject(canbus_bus_t *b, canbus_client_t *c, const char *reason)
{
    c->rejected++;
    b->rejected++;
    staged_reject(b, c, reason);
    if (c->rejected > (uint64_t)b->o.max_rejects) {
        b->garbage_kicks++;
        client_leave(b, c, "garbage");
    }
}

static int members_count(const canbus_bus_t *b)
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
    line_head(&b->staged, b->t, "reject");
    canbus_sb_str(&b->staged, ",\"name\":");
    canbus_sb_mem(&b->staged, c->jname.p, c->jname.n);
    canbus_sb_str(&b->staged, ",\"reason\":\"");
    canbus_sb_str(&b->staged, why);
    canbus_sb_str(&b->staged, "\"}\n");
    send_stop(b, c, reason);
    flush_queue(b, c);
    client_leave(b, c, why);
}

static void handle_hello(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n)
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
    bool lockstep = h.roles & CANBUS_ROLE_LOCKSTEP;
    if (lockstep && b->started && members_count(b) >= b->o.lockstep_clients) {
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
        .flags = b->o.realtime ? CANBUS_WELCOME_REALTIME : 0,
        .quantum_ns = b->o.quantum_ns,
        .t_ns = !b->started ? 0 : c->member_next ? b->t_next : b->t,
        .end_ns = b->o.end_ns,
    };
    client_send(b, c, &wl, sizeof wl);
    if (c->roles & CANBUS_ROLE_CAN) {
        canbus_wire_attach(&b->wire, (uint8_t)c->index, true);
        canbus_wire_arm_recovery(&b->wire, (uint8_t)c->index, b->o.recover);
    }
    /* Command-line faults that name this client are bound to its index. */
    for (size_t i = 0; i < b->o.n_faults && i < b->wire.n_faults; i++) {
        canbus_fault_t *f = &b->wire.faults[i];
        if (f->target == CANBUS_NOBODY && b->o.faults[i].target_name[0] &&
            strcmp(b->o.faults[i].target_name, c->name) == 0)
            f->target = (uint8_t)c->index;
    }
    canbus_sbuf_t *s = &c->staged;
    line_head(s, wl.t_ns, "client_join");
    sb_client(b, s, "name", (uint8_t)c->index);
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
    canbus_sb_str(s, "}\n");
    info(b, "client %d (%s) joined, roles 0x%x", c->index, c->name, c->roles);
}

static void handle_fault(canbus_bus_t *b, canbus_client_t *c, const struct canbus_rec *r)
{
    canbus_fault_t f;
    if (canbus_fault_from_rec(r, &f) || canbus_wire_add_fault(&b->wire, &f)) {
        reject(b, c, "bad_fault");
        return;
    }
    b->faults_armed++;
    canbus_sbuf_t *s = &c->staged;
    line_head(s, b->t, "fault");
    canbus_sb_str(s, ",\"fault\":\"");
    canbus_sb_str(s, canbus_fault_kind_name(f.kind));
    canbus_sb_str(s, "\",\"target\":");
    canbus_sb_u64(s, f.target);
    canbus_sb_str(s, ",\"match_id\":");
    canbus_sb_u64(s, f.match_id);
    canbus_sb_str(s, ",\"from_ns\":");
    canbus_sb_i64(s, f.from_ns);
    canbus_sb_str(s, ",\"until_ns\":");
    canbus_sb_i64(s, f.until_ns == INT64_MAX ? -1 : f.until_ns);
    sb_client(b, s, "by", (uint8_t)c->index);
    canbus_sb_str(s, "}\n");
}

static void handle_records(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n)
{
    for (size_t off = 0; off < n && !c->gone; off += sizeof(struct canbus_rec)) {
        struct canbus_rec r;
        memcpy(&r, p + off, sizeof r);
        switch (r.type) {
        case CANBUS_MSG_FRAME: {
            if (!(c->roles & CANBUS_ROLE_CAN)) {
                reject(b, c, "frame_without_can_role");
                break;
            }
            if (r.len > 8) {
                reject(b, c, "len");
                break;
            }
            if (r.flags & ~(CANBUS_FRAME_EFF | CANBUS_FRAME_RTR)) {
                reject(b, c, "flags");
                break;
            }
            if (r.id > ((r.flags & CANBUS_FRAME_EFF) ? 0x1FFFFFFFu : 0x7FFu)) {
                reject(b, c, "id");
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
                reject(b, c, "out_of_memory");
                break;
            }
            c->tx++;
            break;
        }
        case CANBUS_MSG_DONE:
            if (!c->member || c->done || r.t_ns != b->t_next) {
                reject(b, c, "bad_done");
                break;
            }
            c->done = true;
            break;
        case CANBUS_MSG_STOP:
            if (!b->stopping) {
                b->stopping = true;
                b->stop_reason = CANBUS_STOP_REQUESTED;
                canbus_sbuf_t *s = &c->staged;
                line_head(s, b->t, "stop_request");
                sb_client(b, s, "by", (uint8_t)c->index);
                canbus_sb_str(s, "}\n");
                info(b, "client %d (%s) asked to stop", c->index, c->name);
            }
            break;
        case CANBUS_MSG_FAULT: handle_fault(b, c, &r); break;
        default: reject(b, c, "type"); break;
        }
    }
}

/* Reads what the client has queued, up to a bound so that a flooding client cannot keep
 * the bus in here (well-behaved clients send far fewer datagrams per quantum). */
static void read_client(canbus_bus_t *b, canbus_client_t *c)
{
    for (int k = 0; k < 1024 && !c->gone; k++) {
        struct iovec iov = {.iov_base = b->rxbuf, .iov_len = RXBUF_SIZE};
        struct msghdr m = {.msg_iov = &iov, .msg_iovlen = 1};
        ssize_t n = recvmsg(c->fd, &m, MSG_DONTWAIT);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            if (errno != EAGAIN && errno != EWOULDBLOCK)
                client_leave(b, c, "closed");
            return;
        }
        if (n == 0) {
            client_leave(b, c, "closed");
            return;
        }
        if (c->index < 0) {
            handle_hello(b, c, b->rxbuf, (m.msg_flags & MSG_TRUNC) ? 0 : (size_t)n);
            continue;
        }
        if (m.msg_flags & MSG_TRUNC)
            reject(b, c, "too_long");
        else if (n % sizeof(struct canbus_rec))
            reject(b, c, "size");
        else
            handle_records(b, c, b->rxbuf, (size_t)n);
    }
}

static void accept_all(canbus_bus_t *b)
{
    for (;;) {
        int fd = accept4(b->listen_fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0)
            return; /* EAGAIN, or a transient error: the next poll tells */
        if (b->n_live >= (size_t)b->o.max_clients + 32) {
            close(fd); /* connections that never say hello */
            continue;
        }
        int sz = 4 << 20;
        if (setsockopt(fd, SOL_SOCKET, SO_SNDBUFFORCE, &sz, sizeof sz))
            (void)setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sz, sizeof sz);
        canbus_client_t *c = calloc(1, sizeof *c);
        if (!c) {
            close(fd);
            continue;
        }
        if (b->n_live == b->cap_live) {
            size_t cap = b->cap_live ? b->cap_live * 2 : 16;
            canbus_client_t **v = realloc(b->live, cap * sizeof *v);
            if (!v) {
                free(c);
                close(fd);
                continue;
            }
            b->live = v;
            b->cap_live = cap;
        }
        c->fd = fd;
        c->index = -1;
        struct ucred cred;
        socklen_t len = sizeof cred;
        if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) == 0)
            c->pid = cred.pid;
        b->live[b->n_live++] = c;
    }
}

/* Drops the departed from the live list; welcomed ones stay in by_index for the stats. */
static void reap(canbus_bus_t *b)
{
    size_t k = 0;
    for (size_t i = 0; i < b->n_live; i++) {
        canbus_client_t *c = b->live[i];
        if (!c->gone)
            b->live[k++] = c;
        else if (c->index < 0) {
            trace_write(b, &c->staged);
            canbus_sb_free(&c->staged);
            canbus_sb_free(&c->jname);
            free(c);
        }
    }
    b->n_live = k;
}

/* One poll over everything: accept, read, write queued output, time out stalled tools. */
static void service(canbus_bus_t *b, int64_t timeout_ns)
{
    struct pollfd fds[1 + 512];
    canbus_client_t *who[512];
    size_t n = 0;
    fds[n++] = (struct pollfd){.fd = b->listen_fd, .events = POLLIN};
    for (size_t i = 0; i < b->n_live && n < 1 + 512; i++) {
        canbus_client_t *c = b->live[i];
        who[n - 1] = c;
        short ev = (short)(POLLIN | (queued(c) ? POLLOUT : 0));
        fds[n++] = (struct pollfd){.fd = c->fd, .events = ev};
    }
    struct timespec ts, *tsp = NULL;
    if (timeout_ns >= 0) {
        ts.tv_sec = timeout_ns / 1000000000;
        ts.tv_nsec = timeout_ns % 1000000000;
        tsp = &ts;
    }
    sigset_t none;
    sigemptyset(&none);
    int r = ppoll(fds, n, tsp, &none);
    if (canbus_signalled && !b->stopping) {
        b->stopping = true;
        b->stop_reason = CANBUS_STOP_SIGNAL;
    }
    if (r > 0) {
        if (fds[0].revents & POLLIN)
            accept_all(b);
        for (size_t i = 1; i < n; i++) {
            canbus_client_t *c = who[i - 1];
            if (c->gone)
                continue;
            if (fds[i].revents & POLLOUT)
                flush_queue(b, c);
            if (fds[i].revents & (POLLIN | POLLHUP | POLLERR))
                read_client(b, c);
        }
    }
    int64_t now = wall_ns();
    for (size_t i = 0; i < b->n_live; i++) {
        canbus_client_t *c = b->live[i];
        if (c->gone || !queued(c))
            continue;
        flush_queue(b, c);
        if (queued(c) && !(c->roles & CANBUS_ROLE_LOCKSTEP) &&
            now - c->q_progress_wall > b->o.send_timeout_ns) {
            b->send_timeouts++;
            client_leave(b, c, "send_timeout");
        }
    }
    reap(b);
}

static void read_all(canbus_bus_t *b)
{
    service(b, 0);
    accept_all(b);
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone)
            read_client(b, b->live[i]);
    reap(b);
}

/* ---- the quantum loop ------------------------------------------------------------------- */

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
            }
        }
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < b->n_live; i++) {
            canbus_client_t *c = b->live[i];
            if (c->gone || c->index < 0)
                continue;
            bool ticked = c->member && tick;
            if (ticked != (pass == 1))
                continue;
            size_t n = 0;
            if (c->roles & CANBUS_ROLE_CAN) {
                bool own = c->roles & CANBUS_ROLE_OWN;
                for (size_t k = first; k < last; k++) {
                    const canbus_wire_ev_t *e = &w->ev[k];
                    if (e->kind == CANBUS_EV_TX && e->client == c->index && !own)
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
                b->out[n++] = (struct canbus_rec){.type = CANBUS_MSG_TICK, .t_ns = b->t_next,
                                                  .aux = t};
            }
            for (size_t k = 0; k < n && !c->gone; k += CANBUS_MAX_RECS) {
                size_t m = n - k < CANBUS_MAX_RECS ? n - k : CANBUS_MAX_RECS;
                client_send(b, c, &b->out[k], m * sizeof *b->out);
            }
        }
    }
    w->ev_head = last;
    return 0;
}

/* Waits while a client's output queue is over its limit: a LOCKSTEP client for as long as
 * it takes, any other until the send timeout disconnects it (service()). */
static void wait_queues(canbus_bus_t *b)
{
    for (;;) {
        bool over = false;
        for (size_t i = 0; i < b->n_live; i++)
            if (!b->live[i]->gone && queued(b->live[i]) > b->o.client_buffer)
                over = true;
        if (!over || b->stopping)
            return;
        service(b, 100000000);
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
        line_head(s, b->t, hang ? "node_hang" : "node_kill");
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
            client_leave(b, c, hang ? "node_hung" : "node_killed");
        }
        canbus_sb_str(s, "]}\n");
        trace_write(b, s);
        info(b, "node %u %s at t=%" PRId64 " ns", kill_req->node, hang ? "hung" : "killed", b->t);
    }
}

static int write_wire_trace(canbus_bus_t *b)
{
    canbus_wire_t *w = &b->wire;
    for (; w->ev_mark < w->n_ev; w->ev_mark++)
        trace_wire_event(b, &w->ev[w->ev_mark]);
    return 0;
}

int canbus_bus_run(canbus_bus_t *b)
{
    int rc = 0;
    info(b, "listening on %s, waiting for %d lockstep client(s)", b->o.socket_path,
         b->o.lockstep_clients);
    while (!b->stopping && members_count(b) < b->o.lockstep_clients)
        service(b, -1);
    b->started = true;
    b->start_wall = b->epoch_wall = wall_ns();
    b->t = 0;
    int64_t end = b->o.end_ns < 0 ? INT64_MAX : b->o.end_ns;
    if (!b->stopping)
        info(b, "started");

    while (!b->stopping && b->t < end) {
        b->t_next = end - b->t > b->o.quantum_ns ? b->t + b->o.quantum_ns : end;
        if (b->o.realtime) {
            for (int64_t now; !b->stopping && (now = wall_ns()) < b->epoch_wall + b->t;)
                service(b, b->epoch_wall + b->t - now);
        }
        wait_queues(b);
        if (b->stopping)
            break;
        apply_kills(b);
        flush_staged(b);
        if ((rc = deliver(b, b->t, true)))
            break;
        while (!b->stopping && pending_done(b) > 0)
            service(b, -1);
        if (b->stopping)
            break;
        read_all(b);
        flush_staged(b);
        if ((rc = canbus_wire_run(&b->wire, b->t_next)))
            break;
        write_wire_trace(b);
        b->t = b->t_next;
        b->quanta++;
    }
    if (!b->stopping && rc == 0) {
        b->stop_reason = CANBUS_STOP_END;
        rc = deliver(b, b->t, false);
    }
    b->end_wall = wall_ns();
    flush_staged(b);
    line_head(&b->line, b->t, "bus_stop");
    canbus_sb_str(&b->line, ",\"reason\":\"");
    canbus_sb_str(&b->line, stop_name(b->stop_reason));
    canbus_sb_str(&b->line, "\"}\n");
    trace_write(b, &b->line);
    info(b, "stopping at t=%" PRId64 " ns after %" PRIu64 " quanta, %" PRIu64 " frames", b->t,
         b->quanta, b->wire.frames);

    /* STOP to everyone, then give the queues a bounded time to drain. */
    if (b->listen_fd >= 0) {
        close(b->listen_fd);
        b->listen_fd = -1;
        unlink(b->o.socket_path);
    }
    for (size_t i = 0; i < b->n_live; i++)
        send_stop(b, b->live[i], b->stop_reason);
    int64_t deadline = wall_ns() + 2000000000;
    for (;;) {
        bool any = false;
        for (size_t i = 0; i < b->n_live; i++) {
            canbus_client_t *c = b->live[i];
            if (!c->gone)
                flush_queue(b, c);
            if (!c->gone && queued(c))
                any = true;
        }
        if (!any || wall_ns() > deadline)
            break;
        struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
    }
    return rc;
}

/* ---- set-up, stats ---------------------------------------------------------------------- */

int canbus_bus_open(canbus_bus_t *b, const canbus_opts_t *o)
{
    int rc;
    memset(b, 0, sizeof *b);
    b->o = *o;
    b->next_index = (int)o->n_order; /* clients not in --client-order come after its places */
    b->listen_fd = -1;
    b->stop_reason = CANBUS_STOP_END;
    if ((rc = canbus_wire_init(&b->wire, o->bitrate, o->gap_bits)))
        return rc;
    for (size_t i = 0; i < o->n_faults; i++)
        if ((rc = canbus_wire_add_fault(&b->wire, &o->faults[i].fault)))
            goto fail_wire;
    b->rxbuf = malloc(RXBUF_SIZE);
    if (!b->rxbuf) {
        rc = -ENOMEM;
        goto fail_wire;
    }
    if (o->trace_path) {
        if (strcmp(o->trace_path, "-") == 0)
            b->trace = stdout;
        else if (!(b->trace = fopen(o->trace_path, "w"))) {
            rc = -errno;
            goto fail_rx;
        }
        setvbuf(b->trace, NULL, _IOFBF, 1 << 20);
    }
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (strlen(o->socket_path) >= sizeof sa.sun_path) {
        rc = -ENAMETOOLONG;
        goto fail_trace;
    }
    strcpy(sa.sun_path, o->socket_path);
    b->listen_fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (b->listen_fd < 0) {
        rc = -errno;
        goto fail_trace;
    }
    struct stat st;
    if (lstat(o->socket_path, &st) == 0 && S_ISSOCK(st.st_mode)) {
        /* A socket nobody listens on is stale (an earlier run); a live one is not ours. */
        int probe = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        if (probe >= 0 && connect(probe, (struct sockaddr *)&sa, sizeof sa) == 0) {
            close(probe);
            rc = -EADDRINUSE;
            goto fail_sock;
        }
        if (probe >= 0)
            close(probe);
        unlink(o->socket_path);
    }
    if (bind(b->listen_fd, (struct sockaddr *)&sa, sizeof sa) || listen(b->listen_fd, 128)) {
        rc = -errno;
        goto fail_sock;
    }
    return 0;

fail_sock:
    close(b->listen_fd);
    b->listen_fd = -1;
fail_trace:
    if (b->trace && b->trace != stdout)
        fclose(b->trace);
    b->trace = NULL;
fail_rx:
    free(b->rxbuf);
    b->rxbuf = NULL;
fail_wire:
    canbus_wire_fini(&b->wire);
    return rc;
}

int canbus_bus_write_stats(canbus_bus_t *b, const char *path)
{
    FILE *f = strcmp(path, "-") == 0 ? stdout : fopen(path, "w");
    if (!f)
        return -errno;
    const canbus_wire_t *w = &b->wire;
    double load, max1;
    canbus_wire_load(w, b->t, &load, &max1);
    double wall = b->end_wall > b->start_wall ? (double)(b->end_wall - b->start_wall) / 1e9 : 0;
    fprintf(f,
            "{\"bitrate\":%" PRIu32 ",\"quantum_ns\":%" PRId64 ",\"quanta\":%" PRIu64
            ",\"elapsed_ns\":%" PRId64 ",\"frames\":%" PRIu64 ",\"bits\":%" PRIu64
            ",\"busy_bits\":%" PRIu64 ",\"busy_ns\":%" PRId64 ",\"load\":%.6f,\"load_max_1s\":%.6f"
            ",\"error_frames\":%" PRIu64 ",\"bus_off_events\":%" PRIu64 ",\"dropped\":%" PRIu64
            ",\"rejected\":%" PRIu64 ",\"bad_hellos\":%" PRIu64 ",\"late_joins\":%" PRIu64
            ",\"refused_full\":%" PRIu64 ",\"send_timeouts\":%" PRIu64
            ",\"garbage_disconnects\":%" PRIu64 ",\"faults_armed\":%" PRIu64
            ",\"wall_s\":%.6f,\"frames_per_wall_s\":%.1f,\"stop\":\"%s\",\"clients\":[",
            b->o.bitrate, b->o.quantum_ns, b->quanta, b->t, w->frames, w->frame_bits,
            w->busy_bits, canbus_wire_bit_ns(w, w->busy_bits), load, max1, w->error_frames,
            w->bus_off_events, w->dropped, b->rejected, b->bad_hellos, b->late_joins, b->full,
            b->send_timeouts, b->garbage_kicks, b->faults_armed + b->o.n_faults, wall,
            wall > 0 ? (double)w->frames / wall : 0.0,
            stop_name(b->stop_reason));
    for (int i = 0; i < b->next_index; i++) {
        const canbus_client_t *c = b->by_index[i];
        const canbus_wire_ctl_t *k = &w->ctl[i];
        if (!c)
            continue; /* a --client-order place nobody took */
        fprintf(f,
                "%s{\"index\":%d,\"name\":%.*s,\"roles\":%u,\"tx\":%" PRIu64 ",\"rx\":%" PRIu64
                ",\"rejected\":%" PRIu64 ",\"clamped\":%" PRIu64 ",\"overflow\":%" PRIu64
                ",\"tx_ok\":%" PRIu64
                ",\"tx_errors\":%" PRIu64 ",\"dropped\":%" PRIu64 ",\"bus_off_events\":%" PRIu64
                ",\"tec\":%u,\"rec\":%u,\"state\":\"%s\",\"left\":%s}",
                i ? "," : "", i, (int)c->jname.n, c->jname.p, c->roles, c->tx, c->rx,
                c->rejected, c->clamped, c->overflow, k->tx_ok, k->tx_err, k->dropped,
                k->bus_off_events,
                k->tec, k->rec, state_name(canbus_wire_state(w, (uint8_t)i)),
                c->gone ? "true" : "false");
    }
    fprintf(f, "]}\n");
    int rc = 0;
    if (fflush(f) || ferror(f))
        rc = -EIO;
    if (f != stdout && fclose(f) && !rc)
        rc = -EIO;
    return rc;
}

void canbus_bus_close(canbus_bus_t *b)
{
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone) {
            close(b->live[i]->fd);
            b->live[i]->gone = true;
            if (b->live[i]->index < 0) {
                canbus_sb_free(&b->live[i]->staged);
                canbus_sb_free(&b->live[i]->jname);
                free(b->live[i]);
            }
        }
    for (int i = 0; i < b->next_index; i++) {
        canbus_client_t *c = b->by_index[i];
        if (!c)
            continue;
        free(c->q);
        canbus_sb_free(&c->staged);
        canbus_sb_free(&c->jname);
        free(c);
    }
    free(b->live);
    if (b->listen_fd >= 0) {
        close(b->listen_fd);
        unlink(b->o.socket_path);
    }
    if (b->trace) {
        if (fflush(b->trace))
            b->trace_error = true;
        if (b->trace != stdout)
            fclose(b->trace);
    }
    canbus_sb_free(&b->staged);
    canbus_sb_free(&b->line);
    free(b->out);
    free(b->rxbuf);
    canbus_wire_fini(&b->wire);
}
