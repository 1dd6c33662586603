/* SPDX-License-Identifier: Apache-2.0 */
/* The bus's connections: accepting them, reading what clients send, queueing and sending
 * what they are sent without ever blocking, and dropping them. */
#include "canbus__server.h"

#include <errno.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

int64_t canbus__wall_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

void canbus__client_leave(canbus_bus_t *b, canbus_client_t *c, const char *reason)
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
    canbus__info(b, "client %d (%s) left: %s", c->index, c->name, reason);
    /* Once the run's end is decided (a stop asked for, a signal), leaving is part of that end,
     * not an event of the run: the trace would hold it or not depending on how soon the
     * client went (the world asking to stop, then exiting). */
    if (b->stopping)
        return;
    canbus_sbuf_t *s = &c->staged;
    canbus__line_head(s, b->t, "client_leave");
    canbus__sb_client(b, s, "name", (uint8_t)c->index);
    canbus_sb_str(s, ",\"reason\":\"");
    canbus_sb_str(s, reason);
    canbus_sb_str(s, "\"}\n");
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

size_t canbus__queued(const canbus_client_t *c)
{
    return c->q_len - c->q_head;
}

void canbus__flush_queue(canbus_bus_t *b, canbus_client_t *c)
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
            canbus__client_leave(b, c, "closed");
            return;
        }
        c->q_head += 4 + len;
        c->q_progress_wall = canbus__wall_ns();
    }
}

/* Sends one datagram, in order after what is queued; never blocks (the quantum loop waits
 * for clients whose queue is long, see wait_queues()). */
void canbus__client_send(canbus_bus_t *b, canbus_client_t *c, const void *p, size_t n)
{
    if (c->gone)
        return;
    if (canbus__queued(c) == 0) {
        for (;;) {
            ssize_t r = send(c->fd, p, n, MSG_DONTWAIT | MSG_NOSIGNAL);
            if (r >= 0)
                return;
            if (errno == EINTR)
                continue;
            if (errno == EAGAIN || errno == EWOULDBLOCK)
                break;
            canbus__client_leave(b, c, "closed");
            return;
        }
        c->q_progress_wall = canbus__wall_ns();
    }
    if (enqueue(c, p, n))
        canbus__client_leave(b, c, "out_of_memory");
}

void canbus__send_stop(canbus_bus_t *b, canbus_client_t *c, uint32_t reason)
{
    struct canbus_rec r = {.type = CANBUS_MSG_STOP, .id = reason, .t_ns = b->t};
    canbus__client_send(b, c, &r, sizeof r);
}

/* Reads what the client has queued, up to a bound so that a flooding client cannot keep
 * the bus in here (well-behaved clients send far fewer datagrams per quantum). Up to
 * RX_BATCH datagrams a call: a call that brings fewer than it asked for found the queue
 * empty, so a client that sent one datagram is read with one call, not two (the second
 * saying EAGAIN). */
void canbus__read_client(canbus_bus_t *b, canbus_client_t *c)
{
    struct mmsghdr mm[RX_BATCH];
    struct iovec iov[RX_BATCH];
    c->more = true; /* until a short read or EAGAIN says otherwise */
    for (int k = 0; k < 1024 && !c->gone;) {
        /* A client not yet welcomed is read a datagram at a time: handling its HELLO may read
         * other clients (canbus__handle_hello()), into the same buffer. */
        int want = c->index < 0 ? 1 : 1024 - k < RX_BATCH ? 1024 - k : RX_BATCH;
        for (int j = 0; j < want; j++) {
            iov[j] = (struct iovec){.iov_base = b->rxbuf + (size_t)j * RXBUF_SIZE,
                                    .iov_len = RXBUF_SIZE};
            mm[j] = (struct mmsghdr){.msg_hdr = {.msg_iov = &iov[j], .msg_iovlen = 1}};
        }
        int got = recvmmsg(c->fd, mm, (unsigned)want, MSG_DONTWAIT, NULL);
        if (got < 0) {
            if (errno == EINTR)
                continue;
            c->more = false;
            if (errno != EAGAIN && errno != EWOULDBLOCK)
                canbus__client_leave(b, c, "closed");
            return;
        }
        for (int j = 0; j < got && !c->gone; j++) {
            uint8_t *buf = iov[j].iov_base;
            size_t n = mm[j].msg_len;
            bool trunc = mm[j].msg_hdr.msg_flags & MSG_TRUNC;
            if (n == 0) {
                c->more = false;
                canbus__client_leave(b, c, "closed");
                return;
            }
            if (c->control) { /* a truncated datagram is rejected for its size (1 byte) */
                canbus__handle_control(b, c, buf, trunc ? 1 : n);
                continue;
            }
            if (c->index < 0) {
                canbus__handle_hello(b, c, buf, trunc ? 0 : n);
                continue;
            }
            if (trunc)
                canbus__reject(b, c, "too_long");
            else if (n % sizeof(struct canbus_rec))
                canbus__reject(b, c, "size");
            else
                canbus__handle_records(b, c, buf, n);
        }
        k += got;
        if (got < want) {
            c->more = false;
            return;
        }
    }
}

static void accept_all(canbus_bus_t *b)
{
    for (;;) {
        int fd = accept4(b->listen_fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0)
            return; /* EAGAIN, or a transient error: the next poll tells */
        struct ucred cred;
        socklen_t len = sizeof cred;
        if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0 || cred.uid != getuid()) {
            b->refused_users++; /* only the run's owner may use its bus */
            close(fd);
            continue;
        }
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
        c->pid = cred.pid;
        c->more = true; /* its HELLO may be waiting already */
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
            if (c == b->control)
                b->control = NULL; /* the launcher has gone: no more PROCESS records */
            canbus__trace_write(b, &c->staged);
            canbus_sb_free(&c->staged);
            canbus_sb_free(&c->jname);
            free(c);
        }
    }
    b->n_live = k;
}

/* One poll over everything: accept, read, write queued output, time out stalled tools. */
void canbus__service(canbus_bus_t *b, int64_t timeout_ns)
{
    struct pollfd fds[1 + 512];
    canbus_client_t *who[512];
    size_t n = 0;
    fds[n++] = (struct pollfd){.fd = b->listen_fd, .events = POLLIN};
    for (size_t i = 0; i < b->n_live && n < 1 + 512; i++) {
        canbus_client_t *c = b->live[i];
        who[n - 1] = c;
        short ev = (short)(POLLIN | (canbus__queued(c) ? POLLOUT : 0));
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
                canbus__flush_queue(b, c);
            if (fds[i].revents & (POLLIN | POLLHUP | POLLERR))
                canbus__read_client(b, c);
        }
    }
    int64_t now = canbus__wall_ns();
    for (size_t i = 0; i < b->n_live; i++) {
        canbus_client_t *c = b->live[i];
        if (c->gone || !canbus__queued(c))
            continue;
        canbus__flush_queue(b, c);
        if (canbus__queued(c) && !(c->roles & CANBUS_ROLE_LOCKSTEP) &&
            now - c->q_progress_wall > b->o.send_timeout_ns) {
            b->send_timeouts++;
            canbus__client_leave(b, c, "send_timeout");
        }
    }
    reap(b);
}

/* What a client sends reaches the bus's socket within its own send call, so once every DONE
 * is in, one poll shows every client with something to read: only those are read (no sweep
 * of empty sockets), then once more those a read left at its bound (a flooding client is
 * read at most twice the bound per quantum) and those just accepted. */
void canbus__read_all(canbus_bus_t *b)
{
    canbus__service(b, 0); /* accepts too, when the poll shows someone connecting */
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone && b->live[i]->more)
            canbus__read_client(b, b->live[i]);
    reap(b);
}
