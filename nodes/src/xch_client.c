/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition's client of the node's DDS agent: HELLO/WELCOME, INPUTS/AGREED, publishing. */
#include "xch/client.h"

#include <errno.h>
#include <poll.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

/* Big enough for any valid datagram and then some: a longer one arrives truncated and is
 * rejected by its size. */
#define RX_MAX 1024

long xch_payload_size(unsigned type)
{
    switch (type) {
    case XCH_HELLO:
    case XCH_WELCOME:
        return 0;
    case XCH_INPUTS:
        return (long)sizeof(struct xch_inputs);
    case XCH_AGREED:
        return (long)sizeof(struct xch_agreed);
    case XCH_HEALTH:
        return (long)sizeof(struct xch_health);
    case XCH_TELEMETRY:
        return (long)sizeof(struct xch_telemetry);
    case XCH_MISSION:
        return (long)sizeof(struct xch_mission);
    default:
        return -1;
    }
}

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void fill_hdr(struct xch_hdr *h, uint16_t type, uint32_t node, uint32_t frame,
                     int64_t t_ns)
{
    memset(h, 0, sizeof *h);
    h->magic = XCH_MAGIC;
    h->version = XCH_VERSION;
    h->type = type;
    h->node = node;
    h->frame = frame;
    h->t_ns = t_ns;
}

static int send_dgram(int fd, const void *buf, size_t len)
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

/* Waits until fd is readable or the deadline (ms on CLOCK_MONOTONIC, < 0: none) passes. */
static int wait_readable(int fd, int64_t deadline_ms)
{
    for (;;) {
        int timeout = -1;
        if (deadline_ms >= 0) {
            int64_t left = deadline_ms - now_ms();
            if (left <= 0)
                return -ETIMEDOUT;
            timeout = left > 1000000 ? 1000000 : (int)left;
        }
        struct pollfd p = {.fd = fd, .events = POLLIN};
        int n = poll(&p, 1, timeout);
        if (n > 0)
            return 0; /* readable, or hung up: recv says which */
        if (n < 0 && errno != EINTR)
            return -errno;
    }
}

/* Receives one datagram; returns its length, -ESHUTDOWN at end of stream, or -errno. */
static long recv_dgram(int fd, void *buf, size_t cap)
{
    for (;;) {
        ssize_t n = recv(fd, buf, cap, MSG_DONTWAIT);
        if (n > 0)
            return (long)n;
        if (n == 0)
            return -ESHUTDOWN;
        if (errno == EINTR)
            continue;
        return -errno;
    }
}

static bool hdr_ok(const struct xch_hdr *h, long n, uint16_t type, uint32_t node)
{
    return n == (long)sizeof *h + xch_payload_size(type) && h->magic == XCH_MAGIC &&
           h->version == XCH_VERSION && h->type == type && h->node == node;
}

int xch_client_connect(xch_client_t *c, const char *path, unsigned node, char *err,
                       size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->fd = -1;
    c->timeout_ms = XCH_CLIENT_EXCHANGE_TIMEOUT_MS;
    if (node < 1 || node > XCH_MAX_NODES) {
        snprintf(err, errlen, "node %u out of range 1..%d", node, XCH_MAX_NODES);
        return -EINVAL;
    }
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (!path || !*path || strlen(path) >= sizeof sa.sun_path) {
        snprintf(err, errlen, "DDS agent socket path missing or longer than %zu bytes",
                 sizeof sa.sun_path - 1);
        return -ENAMETOOLONG;
    }
    memcpy(sa.sun_path, path, strlen(path) + 1);
    int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        int e = errno;
        snprintf(err, errlen, "socket: %s", strerror(e));
        return -e;
    }
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        int e = errno;
        snprintf(err, errlen, "cannot connect to the DDS agent at %s: %s", path, strerror(e));
        close(fd);
        return -e;
    }
    struct xch_hdr h;
    fill_hdr(&h, XCH_HELLO, node, 0, 0);
    int rc = send_dgram(fd, &h, sizeof h);
    if (rc != 0) {
        snprintf(err, errlen, "DDS agent hello: %s", strerror(-rc));
        close(fd);
        return rc;
    }
    union {
        struct xch_hdr h;
        unsigned char raw[RX_MAX];
    } u;
    rc = wait_readable(fd, now_ms() + XCH_CLIENT_CONNECT_TIMEOUT_MS);
    long n = rc == 0 ? recv_dgram(fd, &u, sizeof u) : rc;
    if (n < 0) {
        snprintf(err, errlen, "no welcome from the DDS agent at %s: %s", path,
                 n == -ESHUTDOWN ? "it closed the connection" : strerror((int)-n));
        close(fd);
        return (int)n;
    }
    if (!hdr_ok(&u.h, n, XCH_WELCOME, node) || u.h.frame < 1 || u.h.frame > XCH_MAX_NODES) {
        snprintf(err, errlen, "the DDS agent at %s did not answer with a welcome for node %u",
                 path, node);
        close(fd);
        return -EPROTO;
    }
    c->fd = fd;
    c->node = node;
    c->nodes = u.h.frame;
    return 0;
}

int xch_client_send(xch_client_t *c, uint16_t type, uint32_t frame, int64_t t_ns,
                    const void *payload, size_t len)
{
    if (c->fd < 0)
        return -ENOTCONN;
    if (type == XCH_HELLO || type == XCH_WELCOME || type == XCH_AGREED ||
        xch_payload_size(type) != (long)len || (len && !payload))
        return -EINVAL;
    union {
        struct {
            struct xch_hdr h;
            struct xch_inputs p; /* the largest payload io sends */
        } s;
        unsigned char raw[sizeof(struct xch_hdr) + sizeof(struct xch_inputs)];
    } u;
    _Static_assert(sizeof(struct xch_inputs) >= sizeof(struct xch_telemetry) &&
                       sizeof(struct xch_inputs) >= sizeof(struct xch_health) &&
                       sizeof(struct xch_inputs) >= sizeof(struct xch_mission),
                   "inputs are the largest io payload");
    fill_hdr(&u.s.h, type, c->node, frame, t_ns);
    memcpy(u.raw + sizeof u.s.h, payload, len);
    return send_dgram(c->fd, u.raw, sizeof u.s.h + len);
}

int xch_client_await(xch_client_t *c, uint32_t frame, struct xch_agreed *out, int timeout_ms)
{
    if (c->fd < 0)
        return -ENOTCONN;
    int64_t deadline = timeout_ms < 0 ? -1 : now_ms() + timeout_ms;
    union {
        struct {
            struct xch_hdr h;
            struct xch_agreed a;
        } s;
        unsigned char raw[RX_MAX];
    } u;
    for (;;) {
        int rc = wait_readable(c->fd, deadline);
        if (rc != 0)
            return rc;
        long n = recv_dgram(c->fd, &u, sizeof u);
        if (n == -EAGAIN || n == -EWOULDBLOCK)
            continue;
        if (n < 0)
            return (int)n;
        if (!hdr_ok(&u.s.h, n, XCH_AGREED, c->node)) {
            c->rejected++;
            continue;
        }
        if (u.s.h.frame != frame) {
            c->stale++; /* an answer to an exchange given up on earlier */
            continue;
        }
        memcpy(out, &u.s.a, sizeof *out);
        return 0;
    }
}

int xch_client_exchange(xch_client_t *c, uint32_t frame, int64_t t_ns,
                        const struct xch_inputs *mine, struct xch_agreed *out)
{
    int rc = xch_client_send(c, XCH_INPUTS, frame, t_ns, mine, sizeof *mine);
    if (rc != 0)
        return rc;
    return xch_client_await(c, frame, out, c->timeout_ms);
}

void xch_client_close(xch_client_t *c)
{
    if (c->fd >= 0)
        close(c->fd);
    c->fd = -1;
}
