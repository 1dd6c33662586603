/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition's xch client under the system partitions' seccomp policy, against a fake agent.
 *
 * The child installs the RUN filter an io partition runs under (ske_sandbox_build with
 * SKE_SANDBOX_IO) and then does everything the io partition does with the client: connect,
 * exchange, publish, time out, close. A call outside the policy kills it with SIGSYS. The
 * parent plays the agent and checks every datagram. (Sanitizer builds skip the filter: their
 * runtime makes calls a partition may not.) */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ske_abi.h"
#include "ske_sandbox.h"
#include "xch/client.h"
#include "rpas/unit_check.h"

#if defined(__SANITIZE_ADDRESS__)
#define SANDBOXED 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SANDBOXED 0
#endif
#endif
#ifndef SANDBOXED
#define SANDBOXED 1
#endif

/* ---- the child: an io partition ------------------------------------------------------ */

static int child(const char *path)
{
    if (SANDBOXED) {
        ske_sandbox_policy_t pol = {.flags = SKE_SANDBOX_IO, .self = getpid()};
        static ske_sandbox_prog_t prog;
        if (ske_sandbox_build(&pol, SKE_SANDBOX_RUN, &prog) != 0 ||
            ske_sandbox_install(&prog) != 0) {
            fprintf(stderr, "child: cannot install the partition filter\n");
            return 10;
        }
    }
    xch_client_t c;
    char err[256];
    int rc = xch_client_connect(&c, path, 2, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "child: connect: %s\n", err);
        return 11;
    }
    if (c.nodes != 3)
        return 12;
    struct xch_inputs mine;
    memset(&mine, 0, sizeof mine);
    mine.valid = XCH_IN_GPS | XCH_IN_AIR;
    mine.wait_mask = 7;
    mine.gps[0] = 47.25;
    struct xch_agreed g;
    rc = xch_client_exchange(&c, 7, 350000000, &mine, &g);
    if (rc != 0 || g.present != 0x3 || g.in[0].gps_seq != 99 || g.in[1].gps[0] != 47.25)
        return 13;
    if (c.stale != 1 || c.rejected != 5)
        return 14;
    struct xch_health h = {.membership = 7, .fcs_mode = 2};
    struct xch_telemetry t = {.fcs_mode = 2, .lat_deg = 1.5};
    struct xch_mission m = {.mode = 3, .alt_ft = 3000};
    if (xch_client_send(&c, XCH_HEALTH, 7, 350000000, &h, sizeof h) != 0 ||
        xch_client_send(&c, XCH_TELEMETRY, 7, 350000000, &t, sizeof t) != 0 ||
        xch_client_send(&c, XCH_MISSION, 7, 350000000, &m, sizeof m) != 0)
        return 15;
    if (xch_client_send(&c, XCH_HEALTH, 7, 0, &h, sizeof h - 1) != -EINVAL ||
        xch_client_send(&c, XCH_AGREED, 7, 0, &g, sizeof g) != -EINVAL ||
        xch_client_send(&c, XCH_HELLO, 7, 0, NULL, 0) != -EINVAL ||
        xch_client_send(&c, XCH_WELCOME, 7, 0, NULL, 0) != -EINVAL ||
        xch_client_send(&c, XCH_HEALTH, 7, 0, NULL, sizeof h) != -EINVAL ||
        xch_client_send(&c, 999, 7, 0, &h, sizeof h) != -EINVAL)
        return 16;
    /* nothing comes for frame 8: the wait ends by its timeout */
    if (xch_client_await(&c, 8, &g, 50) != -ETIMEDOUT)
        return 17;
    /* the agent goes away */
    if (xch_client_await(&c, 9, &g, 5000) != -ESHUTDOWN)
        return 18;
    xch_client_close(&c);
    return 0;
}

/* ---- the parent: the agent ----------------------------------------------------------- */

static long recv_hdr(int fd, struct xch_hdr *h, void *payload, size_t cap)
{
    unsigned char buf[1024];
    ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n < (ssize_t)sizeof *h)
        return -1;
    memcpy(h, buf, sizeof *h);
    if ((size_t)n - sizeof *h > cap)
        return -1;
    memcpy(payload, buf + sizeof *h, (size_t)n - sizeof *h);
    return (long)n;
}

static void send_agreed(int fd, uint32_t node, uint32_t frame, const struct xch_agreed *g)
{
    struct {
        struct xch_hdr h;
        struct xch_agreed g;
    } m = {.h = {XCH_MAGIC, XCH_VERSION, XCH_AGREED, node, frame, 0}, .g = *g};
    CHECK(send(fd, &m, sizeof m, 0) == (ssize_t)sizeof m);
}

static void agent(int lfd)
{
    int fd = accept(lfd, NULL, NULL);
    CHECK(fd >= 0);
    struct xch_hdr h;
    union {
        struct xch_inputs in;
        struct xch_health h;
        struct xch_telemetry t;
        struct xch_mission m;
    } p;
    CHECK(recv_hdr(fd, &h, &p, sizeof p) == (long)sizeof h);
    CHECK(h.magic == XCH_MAGIC && h.version == XCH_VERSION && h.type == XCH_HELLO && h.node == 2);
    struct xch_hdr w = {XCH_MAGIC, XCH_VERSION, XCH_WELCOME, 2, 3, 0};
    CHECK(send(fd, &w, sizeof w, 0) == (ssize_t)sizeof w);

    CHECK(recv_hdr(fd, &h, &p, sizeof p) == (long)(sizeof h + sizeof p.in));
    CHECK(h.type == XCH_INPUTS && h.frame == 7 && h.t_ns == 350000000);
    CHECK(p.in.wait_mask == 7 && p.in.gps[0] == 47.25);
    struct xch_agreed g;
    memset(&g, 0, sizeof g);
    send_agreed(fd, 2, 6, &g); /* an old frame's answer: skipped */
    /* rejected: not an answer (a welcome; short; another node's; wrong magic or version) */
    struct xch_hdr junk = {XCH_MAGIC, XCH_VERSION, XCH_WELCOME, 2, 3, 0};
    CHECK(send(fd, &junk, sizeof junk, 0) == (ssize_t)sizeof junk);
    junk.type = XCH_AGREED;
    CHECK(send(fd, &junk, sizeof junk, 0) == (ssize_t)sizeof junk);
    struct {
        struct xch_hdr h;
        struct xch_agreed g;
    } wrong[] = {{{XCH_MAGIC, XCH_VERSION, XCH_AGREED, 1, 7, 0}, g},
                 {{XCH_MAGIC ^ 1, XCH_VERSION, XCH_AGREED, 2, 7, 0}, g},
                 {{XCH_MAGIC, XCH_VERSION + 1, XCH_AGREED, 2, 7, 0}, g}};
    CHECK(send(fd, wrong, sizeof wrong[0], 0) == (ssize_t)sizeof wrong[0]);
    CHECK(send(fd, wrong + 1, sizeof wrong[0], 0) == (ssize_t)sizeof wrong[0]);
    CHECK(send(fd, wrong + 2, sizeof wrong[0], 0) == (ssize_t)sizeof wrong[0]);
    g.present = 0x3;
    g.in[0].gps_seq = 99;
    g.in[1] = p.in;
    send_agreed(fd, 2, 7, &g);

    CHECK(recv_hdr(fd, &h, &p, sizeof p) == (long)(sizeof h + sizeof p.h));
    CHECK(h.type == XCH_HEALTH && p.h.membership == 7);
    CHECK(recv_hdr(fd, &h, &p, sizeof p) == (long)(sizeof h + sizeof p.t));
    CHECK(h.type == XCH_TELEMETRY && p.t.lat_deg == 1.5);
    CHECK(recv_hdr(fd, &h, &p, sizeof p) == (long)(sizeof h + sizeof p.m));
    CHECK(h.type == XCH_MISSION && p.m.alt_ft == 3000);
    usleep(200000); /* past the child's 50 ms timeout */
    close(fd);
}

/* ---- joins that fail: each says why, and leaves the client unconnected ---------------- */

static int listen_at(const char *path)
{
    int lfd = socket(AF_UNIX, SOCK_SEQPACKET, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", path);
    unlink(path);
    if (lfd < 0 || bind(lfd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(lfd, 1) != 0)
        return -1;
    return lfd;
}

/* An agent that takes the hello, then answers `reply` (len bytes; none: it hangs up). */
static pid_t bad_agent(const char *path, const void *reply, size_t len)
{
    int lfd = listen_at(path);
    CHECK(lfd >= 0);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int fd = accept(lfd, NULL, NULL);
        struct xch_hdr h;
        if (fd < 0 || recv(fd, &h, sizeof h, 0) != (ssize_t)sizeof h)
            _exit(1);
        if (len)
            send(fd, reply, len, 0);
        close(fd);
        _exit(0);
    }
    close(lfd);
    return pid;
}

static void check_refused(const char *path, unsigned node, int rc_expected, const char *says)
{
    xch_client_t c;
    char err[256] = "";
    int rc = xch_client_connect(&c, path, node, err, sizeof err);
    CHECK(rc == rc_expected);
    CHECK(strstr(err, says) != NULL);
    CHECK(c.fd == -1);
    if (rc != rc_expected || !strstr(err, says))
        fprintf(stderr, "  got %d '%s', expected %d '%s'\n", rc, err, rc_expected, says);
}

static void test_joins_that_fail(const char *path)
{
    check_refused(path, 0, -EINVAL, "node 0 out of range 1..3");
    check_refused(path, 4, -EINVAL, "node 4 out of range");
    check_refused("", 1, -ENAMETOOLONG, "socket path missing");
    char longpath[200];
    memset(longpath, 'x', sizeof longpath - 1);
    longpath[sizeof longpath - 1] = '\0';
    check_refused(longpath, 1, -ENAMETOOLONG, "longer than");
    unlink(path);
    check_refused(path, 1, -ENOENT, "cannot connect to the DDS agent at");

    pid_t pid = bad_agent(path, NULL, 0);
    check_refused(path, 2, -ESHUTDOWN, "it closed the connection");
    waitpid(pid, NULL, 0);
    struct xch_hdr other = {XCH_MAGIC, XCH_VERSION, XCH_WELCOME, 1, 3, 0}; /* node 1's */
    pid = bad_agent(path, &other, sizeof other);
    check_refused(path, 2, -EPROTO, "did not answer with a welcome for node 2");
    waitpid(pid, NULL, 0);
    /* each field of the welcome wrong in turn: node counts 0 and 33, magic, version, type,
     * and a datagram longer than a welcome */
    struct {
        struct xch_hdr h;
        uint32_t extra;
    } bad[] = {
        {{XCH_MAGIC, XCH_VERSION, XCH_WELCOME, 2, 0, 0}, 0},
        {{XCH_MAGIC, XCH_VERSION, XCH_WELCOME, 2, XCH_MAX_NODES + 1, 0}, 0},
        {{XCH_MAGIC ^ 1, XCH_VERSION, XCH_WELCOME, 2, 3, 0}, 0},
        {{XCH_MAGIC, XCH_VERSION + 1, XCH_WELCOME, 2, 3, 0}, 0},
        {{XCH_MAGIC, XCH_VERSION, XCH_HEALTH, 2, 3, 0}, 0},
        {{XCH_MAGIC, XCH_VERSION, XCH_WELCOME, 2, 3, 0}, 1},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pid = bad_agent(path, &bad[i], sizeof bad[i].h + (bad[i].extra ? sizeof bad[i].extra : 0));
        check_refused(path, 2, -EPROTO, "did not answer with a welcome");
        waitpid(pid, NULL, 0);
    }

    /* Not connected: nothing to send on or wait for. */
    xch_client_t c;
    char err[64];
    (void)xch_client_connect(&c, path, 9, err, sizeof err);
    struct xch_agreed g;
    struct xch_inputs in = {0};
    CHECK(xch_client_send(&c, XCH_HEALTH, 1, 0, &in, sizeof(struct xch_health)) == -ENOTCONN);
    CHECK(xch_client_await(&c, 1, &g, 0) == -ENOTCONN);
    CHECK(xch_client_exchange(&c, 1, 0, &in, &g) == -ENOTCONN);
    xch_client_close(&c);
    unlink(path);
}

int main(void)
{
    char dir[] = "/tmp/xch-client-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    char path[64];
    snprintf(path, sizeof path, "%s/xch.sock", dir);
    test_joins_that_fail(path);
    int lfd = listen_at(path);
    if (lfd < 0)
        return 1;
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        close(lfd);
        exit(child(path)); /* exit, not _exit: a coverage build writes the child's counters */
    }
    agent(lfd);
    int st = 0;
    waitpid(pid, &st, 0);
    if (WIFSIGNALED(st)) {
        fprintf(stderr, "the client was killed by signal %d%s\n", WTERMSIG(st),
                WTERMSIG(st) == SIGSYS ? ": it made a call outside the partition policy" : "");
        unit_failures++;
    } else {
        CHECK(WEXITSTATUS(st) == 0);
        if (WEXITSTATUS(st))
            fprintf(stderr, "client step %d failed\n", WEXITSTATUS(st));
    }
    close(lfd);
    unlink(path);
    rmdir(dir);
    if (unit_failures) {
        fprintf(stderr, "test_xch_client: %d check(s) failed\n", unit_failures);
        return 1;
    }
    printf("test_xch_client: ok%s\n", SANDBOXED ? " (under the io partition's seccomp filter)" : "");
    return 0;
}
