/* SPDX-License-Identifier: Apache-2.0 */
/* C client of the virtual CAN bus: connection, batching of frames, the lockstep exchange. */
#include "canbus/client.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

static int send_all(int fd, const void *buf, size_t len)
{
    for (;;) {
        ssize_t n = send(fd, buf, len, MSG_NOSIGNAL);
        if (n == (ssize_t)len)
            return 0;
        if (n < 0 && errno == EINTR)
            continue;
        return n < 0 ? -errno : -EMSGSIZE;
    }
}

static void queue_in(canbus_client_t *c, const struct canbus_rec *r)
{
    if (c->in_count == CANBUS_IN_RECS) { /* nobody reads: keep the newest */
        c->in_head = (c->in_head + 1) % CANBUS_IN_RECS;
        c->in_count--;
        c->overflowed++;
    }
    c->in[(c->in_head + c->in_count) % CANBUS_IN_RECS] = *r;
    c->in_count++;
}

/* Reads one datagram and sorts its records. Returns 1 if one was read, 0 if none was waiting
 * (non-blocking), a negative errno on error, -ESHUTDOWN when the bus closed. */
static int read_datagram(canbus_client_t *c, bool block)
{
    ssize_t n = recv(c->fd, c->rx, sizeof c->rx, block ? 0 : MSG_DONTWAIT);
    if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK)
            return 0;
        if (errno != ECONNRESET)
            return -errno;
        n = 0; /* the bus closed with records of ours unread: it is gone all the same */
    }
    if (n == 0) {
        c->stopped = true;
        return -ESHUTDOWN;
    }
    if (n % (ssize_t)sizeof(struct canbus_rec) != 0) {
        c->rejected++;
        return 1;
    }
    int k = (int)(n / (ssize_t)sizeof(struct canbus_rec));
    for (int i = 0; i < k; i++) {
        const struct canbus_rec *r = &c->rx[i];
        switch (r->type) {
        case CANBUS_MSG_FRAME:
            if (r->len > 8) {
                c->rejected++;
                break;
            }
            queue_in(c, r);
            break;
        case CANBUS_MSG_ERROR:
            queue_in(c, r);
            break;
        case CANBUS_MSG_TICK:
            if (r->t_ns > c->granted_ns)
                c->granted_ns = r->t_ns;
            c->ticked = true;
            if (c->flags & CANBUS_WELCOME_REALTIME) {
                uint64_t late = 0;
                for (int b = 0; b < 8; b++)
                    late |= (uint64_t)r->data[b] << (8 * b);
                struct timespec ts;
                clock_gettime(CLOCK_MONOTONIC, &ts);
                c->tick_mono_ns = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
                c->tick_late_ns = (int64_t)late;
                c->tick_start_ns = r->aux;
            }
            break;
        case CANBUS_MSG_STOP:
            c->stopped = true;
            c->stop_reason = r->id;
            break;
        default:
            c->rejected++;
        }
    }
    return 1;
}

int canbus_client_connect(canbus_client_t *c, const char *path, const char *name, uint16_t roles,
                          uint32_t node, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->fd = -1;
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (!path || strlen(path) >= sizeof sa.sun_path) {
        snprintf(err, errlen, "CAN bus socket path missing or longer than %zu bytes",
                 sizeof sa.sun_path - 1);
        return -ENAMETOOLONG;
    }
    strcpy(sa.sun_path, path);
    int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        int e = errno;
        snprintf(err, errlen, "socket: %s", strerror(e));
        return -e;
    }
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        int e = errno;
        snprintf(err, errlen, "cannot connect to the CAN bus at %s: %s", path, strerror(e));
        close(fd);
        return -e;
    }
    struct canbus_hello h = {.magic = CANBUS_MAGIC, .version = CANBUS_VERSION, .roles = roles,
                             .node = node};
    snprintf(h.name, sizeof h.name, "%s", name ? name : "");
    int rc = send_all(fd, &h, sizeof h);
    if (rc != 0) {
        snprintf(err, errlen, "CAN bus hello: %s", strerror(-rc));
        close(fd);
        return rc;
    }
    union {
        struct canbus_welcome w;
        struct canbus_rec r;
        unsigned char raw[64];
    } u;
    ssize_t n;
    do
        n = recv(fd, &u, sizeof u, 0);
    while (n < 0 && errno == EINTR);
    if (n == (ssize_t)sizeof u.r && u.r.type == CANBUS_MSG_STOP) {
        snprintf(err, errlen, "the CAN bus refused us (reason %u)", u.r.id);
        close(fd);
        return -ECONNREFUSED;
    }
    if (n != (ssize_t)sizeof u.w || u.w.magic != CANBUS_MAGIC || u.w.version != CANBUS_VERSION) {
        snprintf(err, errlen, "the CAN bus at %s did not answer with a welcome", path);
        close(fd);
        return -EPROTO;
    }
    c->fd = fd;
    c->index = u.w.client;
    c->bitrate = u.w.bitrate;
    c->flags = u.w.flags;
    c->quantum_ns = u.w.quantum_ns;
    c->end_ns = u.w.end_ns;
    c->granted_ns = u.w.t_ns;
    return CANBUS_OK;
}

int canbus_client_flush(canbus_client_t *c)
{
    if (c->out_n == 0)
        return CANBUS_OK;
    int rc = send_all(c->fd, c->out, (size_t)c->out_n * sizeof c->out[0]);
    c->out_n = 0;
    return rc;
}

static int queue_out(canbus_client_t *c, const struct canbus_rec *r)
{
    if (c->out_n == CANBUS_OUT_RECS) {
        int rc = canbus_client_flush(c);
        if (rc != 0)
            return rc;
    }
    c->out[c->out_n++] = *r;
    return CANBUS_OK;
}

int canbus_client_send(canbus_client_t *c, uint32_t id, bool extended, const uint8_t *data,
                       uint8_t len, int64_t t_ns)
{
    if (len > 8 || id > (extended ? 0x1FFFFFFFu : 0x7FFu))
        return -EINVAL;
    struct canbus_rec r = {.type = CANBUS_MSG_FRAME,
                           .flags = extended ? CANBUS_FRAME_EFF : 0,
                           .len = len,
                           .id = id,
                           .t_ns = t_ns};
    if (len)
        memcpy(r.data, data, len);
    return queue_out(c, &r);
}

int canbus_client_recv(canbus_client_t *c, struct canbus_rec *rec)
{
    if (c->in_count == 0 && !c->stopped) {
        /* Take everything the bus has queued for us, a datagram at a time. */
        int rc;
        while (c->in_count < CANBUS_IN_RECS / 2 && (rc = read_datagram(c, false)) == 1)
            ;
    }
    if (c->in_count == 0)
        return c->stopped ? -ESHUTDOWN : 0;
    *rec = c->in[c->in_head];
    c->in_head = (c->in_head + 1) % CANBUS_IN_RECS;
    c->in_count--;
    return 1;
}

int canbus_client_done_wait(canbus_client_t *c)
{
    return canbus_client_done_wait_for(c, 0);
}

int canbus_client_done_wait_for(canbus_client_t *c, int64_t need_ns)
{
    int rc;
    if (c->stopped)
        return CANBUS_STOPPED;
    if (!c->waiting) {
        /* Before the first TICK there is nothing to report done. */
        if (c->ticked) {
            struct canbus_rec r = {.type = CANBUS_MSG_DONE, .t_ns = c->granted_ns,
                                   .aux = need_ns > c->granted_ns ? need_ns : 0};
            if ((rc = queue_out(c, &r)) != 0)
                return rc;
        }
        if ((rc = canbus_client_flush(c)) != 0) {
            /* The bus has closed the connection (it ended the run while this DONE was on
             * its way): the same as reading its end of file. */
            if (rc == -EPIPE || rc == -ECONNRESET) {
                c->stopped = true;
                return CANBUS_STOPPED;
            }
            return rc;
        }
        c->waiting = true;
        c->wait_from_ns = c->ticked ? c->granted_ns : INT64_MIN;
    }
    /* Called again after EINTR, it goes on waiting without a second DONE. */
    while (!c->stopped && (!c->ticked || c->granted_ns <= c->wait_from_ns)) {
        rc = read_datagram(c, true);
        if (rc == -ESHUTDOWN)
            break;
        if (rc < 0)
            return rc;
    }
    c->waiting = false;
    return c->stopped ? CANBUS_STOPPED : CANBUS_OK;
}

int canbus_client_request_stop(canbus_client_t *c)
{
    struct canbus_rec r = {.type = CANBUS_MSG_STOP, .id = CANBUS_STOP_REQUESTED};
    int rc = queue_out(c, &r);
    return rc ? rc : canbus_client_flush(c);
}

void canbus_client_close(canbus_client_t *c)
{
    if (c->fd >= 0) {
        canbus_client_flush(c);
        close(c->fd);
    }
    c->fd = -1;
}
