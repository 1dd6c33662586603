/* SPDX-License-Identifier: Apache-2.0 */
/* The agent's end of the cross-channel link to its io partition (xch/proto.h). */
#include <errno.h>
#include <inttypes.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include "agent__agent.h"
#include "xch/client.h"

#define RX_MAX 2048         /* a longer datagram is rejected whole */
#define READS_PER_WAKE 64   /* then DDS gets its turn */
#define BAD_TRACED_MAX 1000 /* later bad datagrams are only counted */

int agent_io_listen(agent_t *a)
{
    const char *path = a->o.socket_path;
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (strlen(path) >= sizeof sa.sun_path) {
        fprintf(stderr, "ima-dds-node %s: socket path longer than %zu bytes: %s\n", a->node_name,
                sizeof sa.sun_path - 1, path);
        return -1;
    }
    memcpy(sa.sun_path, path, strlen(path) + 1);
    struct stat st;
    if (lstat(path, &st) == 0) {
        if (!S_ISSOCK(st.st_mode)) {
            fprintf(stderr, "ima-dds-node %s: %s exists and is not a socket\n", a->node_name,
                    path);
            return -1;
        }
        /* A socket nobody listens on is left over from a run that died: take its place. */
        int probe = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        if (probe >= 0) {
            int rc = connect(probe, (struct sockaddr *)&sa, sizeof sa);
            close(probe);
            if (rc == 0) {
                fprintf(stderr, "ima-dds-node %s: another agent is listening at %s\n",
                        a->node_name, path);
                return -1;
            }
        }
        unlink(path);
    }
    int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    /* 0600: only the run's owner may connect (checked again at accept) */
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 ||
        chmod(path, S_IRUSR | S_IWUSR) != 0 || listen(fd, 4) != 0) {
        fprintf(stderr, "ima-dds-node %s: cannot listen at %s: %s\n", a->node_name, path,
                strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    a->listen_fd = fd;
    return 0;
}

static void take_io(agent_t *a, int fd)
{
    a->io_fd = fd;
    a->io_hello = false;
    a->io_connections++;
    agent_trace_simple(a, "io_connect");
}

/* Every connection is taken at once and checked (agent_guard.c): one that may not be io is
 * closed whether or not io's link is up. One that may, while the link is up, is io restarted
 * by its SKE: the old link is read to its end first (its process is gone, its last datagrams
 * are not), and the newcomer waits in io_next_fd if the old one is still open. */
void agent_io_accept(agent_t *a)
{
    int fd = accept4(a->listen_fd, NULL, NULL, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0)
        return; /* EAGAIN, or the peer gave up already */
    if (!agent_guard_may_be_io(a, fd)) {
        close(fd);
        return;
    }
    if (a->io_fd >= 0)
        agent_io_readable(a);
    if (a->io_fd < 0)
        take_io(a, fd);
    else if (a->io_next_fd < 0)
        a->io_next_fd = fd;
    else {
        close(a->io_next_fd); /* the later of two waiting partitions is the live one */
        a->io_next_fd = fd;
    }
}

void agent_io_close(agent_t *a, const char *reason)
{
    if (a->io_fd < 0)
        return;
    close(a->io_fd);
    a->io_fd = -1;
    a->io_hello = false;
    a->pending = false;
    a->io_disconnects++;
    if (agent_trace_begin(a, "io_disconnect")) {
        fprintf(a->trace, ",\"reason\":\"%s\"", reason);
        agent_trace_end(a);
    }
    agent_log(a, "io link closed (%s); waiting for a new connection", reason);
    agent_dds_withdraw(a);
    if (a->io_next_fd >= 0) {
        take_io(a, a->io_next_fd);
        a->io_next_fd = -1;
    }
    /* Closed by the inputs listener, the main thread may be polling the old descriptor. */
    agent_wake(a);
}

void agent_io_shutdown(agent_t *a)
{
    if (a->io_fd >= 0)
        close(a->io_fd);
    a->io_fd = -1;
    if (a->io_next_fd >= 0)
        close(a->io_next_fd);
    a->io_next_fd = -1;
    if (a->listen_fd >= 0) {
        close(a->listen_fd);
        unlink(a->o.socket_path);
    }
    a->listen_fd = -1;
}

static void send_to_io(agent_t *a, const void *buf, size_t len)
{
    ssize_t n = send(a->io_fd, buf, len, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n != (ssize_t)len)
        agent_io_close(a, n < 0 && errno == EAGAIN ? "io_not_reading" : "send_failed");
}

static void bad(agent_t *a, const char *reason, long len, const struct xch_hdr *h)
{
    a->bad_datagrams++;
    if (a->traced_bad >= BAD_TRACED_MAX)
        return;
    a->traced_bad++;
    if (agent_trace_begin(a, "bad_datagram")) {
        fprintf(a->trace, ",\"reason\":\"%s\",\"len\":%ld", reason, len);
        if (h)
            fprintf(a->trace, ",\"type\":%u,\"claimed_node\":%u", h->type, h->node);
        if (a->traced_bad == BAD_TRACED_MAX)
            fputs(",\"more\":\"counted only from here on\"", a->trace);
        agent_trace_end(a);
    }
}

static void send_agreed(agent_t *a, bool timed_out, uint32_t missing)
{
    struct {
        struct xch_hdr h;
        struct xch_agreed g;
    } m;
    memset(&m, 0, sizeof m);
    agree_build(&a->agree, a->pend_frame, a->pend_mask, &m.g);
    m.h = (struct xch_hdr){.magic = XCH_MAGIC, .version = XCH_VERSION, .type = XCH_AGREED,
                           .node = a->o.node, .frame = a->pend_frame, .t_ns = a->pend_t_ns};
    a->pending = false;
    a->agreed++;
    uint32_t awaited = agree_mask(&a->agree, a->pend_mask);
    if ((m.g.present & awaited) != awaited)
        a->partial++;
    if (a->pend_waited)
        a->waits++;
    int64_t lat = agent_mono_ns() - a->pend_start_ns;
    agent_lat_add(&a->xch_lat, lat);
    if (timed_out) {
        a->timeouts++;
        if (agent_trace_begin(a, "xch_timeout")) {
            fprintf(a->trace, ",\"frame\":%u,\"waited_us\":%.1f", a->pend_frame, lat / 1e3);
            agent_trace_nodes(a, "missing", missing);
            agent_trace_end(a);
        }
    }
    send_to_io(a, &m, sizeof m);
}

void agent_io_check_pending(agent_t *a, bool timed_out)
{
    if (!a->pending)
        return;
    uint32_t missing = agree_missing(&a->agree, a->pend_frame, a->pend_mask);
    if (missing && !a->o.realtime && agent_dds_declare_hung(a, missing))
        missing = agree_missing(&a->agree, a->pend_frame, a->pend_mask);
    if (missing && a->o.realtime && agent_mono_ns() - a->pend_start_ns >= a->o.xch_timeout_ns)
        timed_out = true;
    if (missing && !timed_out) {
        a->pend_waited = true;
        return;
    }
    send_agreed(a, missing != 0, missing);
}

void agent_io_catch_up(agent_t *a)
{
    agent_dds_process_events(a);
    agent_dds_take_all(a);
    agent_io_check_pending(a, false);
}

static void on_inputs(agent_t *a, const struct xch_hdr *h, const struct xch_inputs *in)
{
    if (a->pending) {
        /* io asked again before taking its answer: answer the old frame with what is there */
        a->superseded++;
        send_agreed(a, false, 0);
        if (a->io_fd < 0)
            return;
    }
    a->last_t_ns = h->t_ns;
    agree_store(&a->agree, a->o.node, h->frame, h->t_ns, in);
    agent_fault_publish(a, T_INPUTS, h, in);
    a->pending = true;
    a->have_frame = true;
    a->pend_frame = h->frame;
    a->pend_mask = in->wait_mask;
    a->pend_t_ns = h->t_ns;
    a->pend_start_ns = agent_mono_ns();
    a->pend_waited = false;
    agent_io_catch_up(a);
}

static void on_dgram(agent_t *a, const unsigned char *buf, long n)
{
    struct xch_hdr h;
    if (n < (long)sizeof h) {
        bad(a, "short", n, NULL);
        return;
    }
    memcpy(&h, buf, sizeof h);
    if (h.magic != XCH_MAGIC) {
        bad(a, "magic", n, NULL);
        return;
    }
    if (h.version != XCH_VERSION) {
        bad(a, "version", n, &h);
        return;
    }
    long psize = xch_payload_size(h.type);
    if (psize < 0 || h.type == XCH_WELCOME || h.type == XCH_AGREED) {
        bad(a, "type", n, &h);
        return;
    }
    if (n != (long)sizeof h + psize) {
        bad(a, "size", n, &h);
        if (h.type == XCH_HELLO && !a->io_hello)
            agent_io_close(a, "bad_hello");
        return;
    }
    if (h.node != a->o.node) {
        bad(a, "node", n, &h);
        if (h.type == XCH_HELLO && !a->io_hello)
            agent_io_close(a, "bad_hello"); /* an io of another node: tell it at once */
        return;
    }
    if (h.type == XCH_HELLO) {
        if (a->io_hello) {
            bad(a, "hello_again", n, &h);
            return;
        }
        a->io_hello = true;
        struct xch_hdr w = {.magic = XCH_MAGIC, .version = XCH_VERSION, .type = XCH_WELCOME,
                            .node = a->o.node, .frame = a->o.nodes, .t_ns = 0};
        send_to_io(a, &w, sizeof w);
        if (a->io_fd >= 0)
            agent_trace_simple(a, "io_hello");
        return;
    }
    if (!a->io_hello) {
        bad(a, "no_hello", n, &h);
        return;
    }
    const unsigned char *payload = buf + sizeof h;
    switch (h.type) {
    case XCH_INPUTS: {
        struct xch_inputs in;
        memcpy(&in, payload, sizeof in);
        on_inputs(a, &h, &in);
        break;
    }
    case XCH_HEALTH: {
        struct xch_health x;
        memcpy(&x, payload, sizeof x);
        agent_fault_publish(a, T_HEALTH, &h, &x);
        break;
    }
    case XCH_TELEMETRY: {
        struct xch_telemetry x;
        memcpy(&x, payload, sizeof x);
        agent_dds_publish(a, T_TELEMETRY, &h, &x);
        break;
    }
    case XCH_MISSION: {
        struct xch_mission x;
        memcpy(&x, payload, sizeof x);
        agent_dds_publish(a, T_MISSION, &h, &x);
        break;
    }
    }
}

void agent_io_readable(agent_t *a)
{
    static unsigned char buf[RX_MAX] __attribute__((aligned(8)));
    for (int i = 0; i < READS_PER_WAKE && a->io_fd >= 0; i++) {
        struct iovec iov = {buf, sizeof buf};
        struct msghdr msg = {.msg_iov = &iov, .msg_iovlen = 1};
        ssize_t n = recvmsg(a->io_fd, &msg, MSG_DONTWAIT);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK)
                return;
            if (errno == EINTR)
                continue;
            agent_io_close(a, "recv_failed");
            return;
        }
        if (n == 0) {
            agent_io_close(a, "closed");
            return;
        }
        if (msg.msg_flags & MSG_TRUNC) {
            bad(a, "too_long", (long)n, NULL);
            continue;
        }
        on_dgram(a, buf, (long)n);
    }
}
