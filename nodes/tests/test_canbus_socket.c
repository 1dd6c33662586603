/* SPDX-License-Identifier: Apache-2.0 */
/* Socket-level test of the ima-canbus process: lockstep exchange, delivery order and
 * timestamps, stamping of tool frames, malformed input, faults, bus-off, determinism. */
#include "canbus/proto.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "canbus_test.h"

static const char *bus_path;

#define REQUIRE(cond)                                                                         \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            fprintf(stderr, "%s:%d: required: %s\n", __FILE__, __LINE__, #cond);              \
            unit_failures++;                                                                  \
            return -1;                                                                        \
        }                                                                                     \
    } while (0)

#define EXT300 (0x300u << 18 | 5u)

typedef struct {
    int fd;
    int index;
    struct canbus_welcome wl;
} client_t;

static pid_t start_bus(char *const argv[], const char *sock)
{
    pid_t pid = fork();
    if (pid == 0) {
        execv(bus_path, argv);
        perror("execv");
        _exit(127);
    }
    /* Wait until the bus listens: its socket appears at bind(), a moment before listen(), and
     * a connect in between is refused (a slow bus, under ASan on a loaded host, shows it). The
     * probe's connection closes before any hello: the bus forgets it without a trace line. */
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", sock);
    for (int i = 0; i < 500; i++) {
        int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        int rc = fd >= 0 ? connect(fd, (struct sockaddr *)&sa, sizeof sa) : -1;
        if (fd >= 0)
            close(fd);
        if (rc == 0)
            return pid;
        struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
    }
    return pid;
}

static int raw_connect(const char *sock)
{
    int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", sock);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa)) {
        perror("connect");
        if (fd >= 0)
            close(fd);
        return -1;
    }
    struct timeval tv = {5, 0}; /* a hung bus fails the test instead of hanging it */
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    return fd;
}

/* A control channel as the launcher makes it: ctl[0] ours, ctl[1] inherited by the bus (its
 * number in fd_text, for --control-fd; the caller closes ctl[1] once the bus has started). */
static int control_pair(int ctl[2], char *fd_text, size_t len)
{
    REQUIRE(socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, ctl) == 0);
    REQUIRE(fcntl(ctl[1], F_SETFD, 0) == 0);
    snprintf(fd_text, len, "%d", ctl[1]);
    return 0;
}

static int join_node(client_t *c, const char *sock, const char *name, uint16_t roles,
                     uint32_t node)
{
    memset(c, 0, sizeof *c);
    c->fd = raw_connect(sock);
    REQUIRE(c->fd >= 0);
    struct canbus_hello h = {.magic = CANBUS_MAGIC, .version = CANBUS_VERSION, .roles = roles,
                             .node = node};
    snprintf(h.name, sizeof h.name, "%s", name);
    REQUIRE(send(c->fd, &h, sizeof h, 0) == (ssize_t)sizeof h);
    REQUIRE(recv(c->fd, &c->wl, sizeof c->wl, 0) == (ssize_t)sizeof c->wl);
    REQUIRE(c->wl.magic == CANBUS_MAGIC);
    c->index = c->wl.client;
    return 0;
}

static int join(client_t *c, const char *sock, const char *name, uint16_t roles)
{
    return join_node(c, sock, name, roles, 0);
}

/* A hello the bus must refuse: the STOP reason it answers with, or -1. */
static int refused_hello(const char *sock, const char *name, uint16_t roles, uint32_t node)
{
    int fd = raw_connect(sock);
    if (fd < 0)
        return -1;
    struct canbus_hello h = {.magic = CANBUS_MAGIC, .version = CANBUS_VERSION, .roles = roles,
                             .node = node};
    memcpy(h.name, name, strnlen(name, sizeof h.name)); /* a 32-byte name has no NUL */
    struct canbus_rec r;
    int reason = -1;
    if (send(fd, &h, sizeof h, 0) == (ssize_t)sizeof h &&
        recv(fd, &r, sizeof r, 0) == (ssize_t)sizeof r && r.type == CANBUS_MSG_STOP)
        reason = (int)r.id;
    close(fd);
    return reason;
}

static void sendrecs(const client_t *c, const struct canbus_rec *r, size_t n)
{
    CHECK(send(c->fd, r, n * sizeof *r, 0) == (ssize_t)(n * sizeof *r));
}

static struct canbus_rec frame(uint32_t id, uint8_t flags, uint8_t len, int64_t t)
{
    struct canbus_rec r = {.type = CANBUS_MSG_FRAME, .flags = flags, .len = len, .id = id,
                           .t_ns = t};
    for (int i = 0; i < 8; i++)
        r.data[i] = (uint8_t)(id + i);
    return r;
}

static struct canbus_rec done(int64_t t)
{
    return (struct canbus_rec){.type = CANBUS_MSG_DONE, .t_ns = t};
}

/* Reads until a TICK (or STOP); the FRAME and ERROR records before it go to got[]. */
static int until_tick(const client_t *c, struct canbus_rec *got, int max, int *n,
                      struct canbus_rec *tick)
{
    static struct canbus_rec buf[CANBUS_MAX_RECS];
    *n = 0;
    for (;;) {
        ssize_t len = recv(c->fd, buf, sizeof buf, 0);
        if (len <= 0 || len % 32)
            return -1;
        for (int i = 0; i < len / 32; i++) {
            if (buf[i].type == CANBUS_MSG_TICK || buf[i].type == CANBUS_MSG_STOP) {
                *tick = buf[i];
                CHECK_EQ(i, len / 32 - 1); /* nothing after a TICK in its datagram */
                return 0;
            }
            if (*n < max)
                got[(*n)++] = buf[i];
        }
    }
}

static int read_file(const char *path, char *buf, size_t size)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    size_t n = fread(buf, 1, size - 1, f);
    buf[n] = '\0';
    fclose(f);
    return (int)n;
}

static int count(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = hay; (p = strstr(p, needle)); p++)
        n++;
    return n;
}

static int wait_bus(pid_t pid)
{
    int st = -1;
    for (int i = 0; i < 1000; i++) {
        if (waitpid(pid, &st, WNOHANG) == pid)
            return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
        struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
    }
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
    return -1;
}

/* Two LOCKSTEP clients, a passive logger, a garbage client; returns 0 when it ran. */
static int scenario_main(const char *dir, const char *trace_path)
{
    char sock[256], stats_path[256];
    snprintf(sock, sizeof sock, "%s/bus.sock", dir);
    snprintf(stats_path, sizeof stats_path, "%s/stats.json", dir);
    /* The launcher's control channel: FAULT records come over it, not over the socket. */
    int ctl[2];
    char ctl_fd[16];
    REQUIRE(control_pair(ctl, ctl_fd, sizeof ctl_fd) == 0);
    char *argv[] = {(char *)bus_path, "--socket", sock, "--lockstep-clients", "2",
                    "--quantum-us", "1000", "--end-ns", "8000000", "--trace",
                    (char *)trace_path, "--stats", stats_path, "-q", "--control-fd", ctl_fd,
                    NULL};
    pid_t pid = start_bus(argv, sock);
    close(ctl[1]);
    client_t p, a, b, g;
    struct canbus_rec got[64], tick;
    int n;

    REQUIRE(join(&p, sock, "p", CANBUS_ROLE_CAN | CANBUS_ROLE_OWN) == 0);
    CHECK_EQ(p.index, 0);
    CHECK_EQ(p.wl.t_ns, 0);
    CHECK_EQ(p.wl.quantum_ns, 1000000);
    CHECK_EQ(p.wl.end_ns, 8000000);
    CHECK_EQ(p.wl.bitrate, 1000000);
    REQUIRE(join(&a, sock, "a", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP) == 0);
    REQUIRE(join(&b, sock, "b", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP) == 0);
    CHECK_EQ(a.index, 1);
    CHECK_EQ(b.index, 2);

    /* Quantum [0, 1 ms). */
    REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_TICK);
    CHECK_EQ(tick.t_ns, 1000000);
    CHECK_EQ(tick.aux, 0);
    CHECK_EQ(n, 0);
    REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.t_ns, 1000000);
    struct canbus_rec qa[] = {frame(0x200, 0, 8, 0), done(1000000)};
    /* An extended identifier competes by its 11 base bits first: base 0x300 loses to 0x200. */
    struct canbus_rec qb[] = {frame(0x100, 0, 8, 0), frame(EXT300, CANBUS_FRAME_EFF, 8, 100000),
                              done(1000000)};
    sendrecs(&a, qa, 2);
    sendrecs(&b, qb, 3);

    /* [1 ms, 2 ms): 0x100 (B) won at 0, 0x200 (A) next, then B's extended frame. */
    REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.t_ns, 2000000);
    CHECK_EQ(tick.aux, 1000000);
    REQUIRE(n == 2);
    CHECK_EQ(got[0].type, CANBUS_MSG_FRAME);
    CHECK_EQ(got[0].id, 0x100);
    CHECK_EQ(got[0].src, 2);
    CHECK_EQ(got[0].aux, 0);
    CHECK_EQ(got[0].t_ns, 135000);
    CHECK_EQ(got[0].data[7], 0x107 & 0xFF);
    CHECK_EQ(got[1].id, EXT300);
    CHECK_EQ(got[1].flags, CANBUS_FRAME_EFF);
    CHECK_EQ(got[1].aux, 270000);
    CHECK_EQ(got[1].t_ns, 430000);
    REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
    REQUIRE(n == 1);
    CHECK_EQ(got[0].id, 0x200);
    CHECK_EQ(got[0].src, 1);
    CHECK_EQ(got[0].aux, 135000);
    CHECK_EQ(got[0].t_ns, 270000);
    struct canbus_rec qa2[] = {frame(0x400, 0, 8, 1950000), done(2000000)};
    sendrecs(&a, qa2, 2);
    struct canbus_rec d2 = done(2000000);
    sendrecs(&b, &d2, 1);

    /* [2 ms, 3 ms): A's frame is still on the wire at 2 ms: nothing delivered. */
    REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
    CHECK_EQ(n, 0);
    CHECK_EQ(tick.t_ns, 3000000);
    REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
    CHECK_EQ(n, 0);
    /* The logger's frame is stamped by the bus with the quantum start, whatever it says. */
    struct canbus_rec pf = frame(0x050, 0, 8, 999);
    sendrecs(&p, &pf, 1);
    /* Malformed input from a client that joins now. */
    REQUIRE(join(&g, sock, "garbage", CANBUS_ROLE_CAN) == 0);
    CHECK_EQ(g.index, 3);
    CHECK_EQ(g.wl.t_ns, 2000000);
    uint8_t odd[33] = {CANBUS_MSG_FRAME};
    CHECK(send(g.fd, odd, sizeof odd, 0) == (ssize_t)sizeof odd);
    struct canbus_rec bad[5] = {frame(1, 0, 1, 0), frame(2, 0, 9, 0), frame(0x800, 0, 1, 0),
                                frame(0x20000000, CANBUS_FRAME_EFF, 1, 0), frame(3, 0x80, 1, 0)};
    bad[0].type = 99;
    sendrecs(&g, bad, 5);
    /* A bad hello and a late LOCKSTEP client are refused with a reason. */
    int bh = raw_connect(sock);
    REQUIRE(bh >= 0);
    struct canbus_hello h = {.magic = 0x12345678, .version = CANBUS_VERSION};
    CHECK(send(bh, &h, sizeof h, 0) == (ssize_t)sizeof h);
    struct canbus_rec stop;
    CHECK(recv(bh, &stop, sizeof stop, 0) == (ssize_t)sizeof stop);
    CHECK_EQ(stop.type, CANBUS_MSG_STOP);
    CHECK_EQ(stop.id, CANBUS_STOP_BAD_HELLO);
    close(bh);
    int late = raw_connect(sock);
    REQUIRE(late >= 0);
    struct canbus_hello hl = {.magic = CANBUS_MAGIC, .version = CANBUS_VERSION,
                              .roles = CANBUS_ROLE_LOCKSTEP, .name = "late"};
    CHECK(send(late, &hl, sizeof hl, 0) == (ssize_t)sizeof hl);
    CHECK(recv(late, &stop, sizeof stop, 0) == (ssize_t)sizeof stop);
    CHECK_EQ(stop.type, CANBUS_MSG_STOP);
    CHECK_EQ(stop.id, CANBUS_STOP_LATE_JOIN);
    close(late);
    struct canbus_rec d3 = done(3000000);
    sendrecs(&a, &d3, 1);
    sendrecs(&b, &d3, 1);

    /* [3 ms, 4 ms): A's frame (ended 2.085 ms), then the logger's, started at 2.085 ms. */
    REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
    REQUIRE(n == 1);
    CHECK_EQ(got[0].id, 0x050);
    CHECK_EQ(got[0].src, 0);
    CHECK_EQ(got[0].aux, 2085000);
    CHECK_EQ(got[0].t_ns, 2220000);
    REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
    REQUIRE(n == 2);
    CHECK_EQ(got[0].id, 0x400);
    CHECK_EQ(got[0].aux, 1950000);
    CHECK_EQ(got[0].t_ns, 2085000);
    CHECK_EQ(got[1].id, 0x050);
    /* The garbage client still works after its rejects. */
    struct canbus_rec gf = frame(0x055, 0, 8, 0);
    sendrecs(&g, &gf, 1);
    struct canbus_rec d4 = done(4000000);
    sendrecs(&a, &d4, 1);
    sendrecs(&b, &d4, 1);

    /* [4 ms, 5 ms) */
    REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
    REQUIRE(n == 1);
    CHECK_EQ(got[0].id, 0x055);
    CHECK_EQ(got[0].src, 3);
    CHECK_EQ(got[0].aux, 3000000);
    REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
    CHECK_EQ(n, 1);
    /* Then it floods garbage and is disconnected. */
    static struct canbus_rec flood[200];
    memset(flood, 0, sizeof flood);
    sendrecs(&g, flood, 200);
    /* A FAULT record from the launcher: drop the first 0x666 frame. Sent before the frames:
     * the control channel is read first. */
    struct canbus_rec fault = {.type = CANBUS_MSG_FAULT, .flags = 1 /* drop */, .id = 0x666,
                               .t_ns = 0, .aux = 0, .data = {0xFF, 1, 0}};
    CHECK(send(ctl[0], &fault, sizeof fault, 0) == (ssize_t)sizeof fault);
    struct canbus_rec qa5[] = {frame(0x666, 0, 8, 4000000), frame(0x666, 0, 8, 4500000),
                               done(5000000)};
    sendrecs(&a, qa5, 3);
    struct canbus_rec d5 = done(5000000);
    sendrecs(&b, &d5, 1);

    REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
    REQUIRE(n == 1);
    CHECK_EQ(got[0].id, 0x666);
    CHECK_EQ(got[0].aux, 4500000);
    CHECK_EQ(got[0].t_ns, 4635000);
    REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
    CHECK_EQ(n, 0);
    /* To the end: every quantum, DONE; the last TICK grants 8 ms, then STOP(END). */
    for (int64_t t = 6000000; t <= 8000000; t += 1000000) {
        struct canbus_rec d = done(t);
        sendrecs(&a, &d, 1);
        sendrecs(&b, &d, 1);
        REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
        REQUIRE(until_tick(&b, got, 64, &n, &tick) == 0);
        CHECK_EQ(tick.type, t < 8000000 ? CANBUS_MSG_TICK : CANBUS_MSG_STOP);
    }
    CHECK_EQ(tick.id, CANBUS_STOP_END);

    /* The logger saw everything in wire order, its own frame too (OWN). */
    static const uint32_t want[] = {0x100, 0x200, EXT300, 0x400, 0x050, 0x055, 0x666};
    REQUIRE(until_tick(&p, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_STOP);
    CHECK_EQ(n, 7);
    for (int i = 0; i < n && i < 7; i++) {
        CHECK_EQ(got[i].id, want[i]);
        if (i)
            CHECK(got[i].t_ns > got[i - 1].t_ns);
    }
    /* The flooder was cut off: end of stream after what it was sent before. */
    struct canbus_rec junk[CANBUS_MAX_RECS];
    ssize_t r;
    while ((r = recv(g.fd, junk, sizeof junk, 0)) > 0)
        CHECK(junk[0].type != CANBUS_MSG_STOP);
    CHECK(r == 0 || errno == ECONNRESET);
    close(a.fd);
    close(b.fd);
    close(p.fd);
    close(g.fd);
    close(ctl[0]);

    CHECK_EQ(wait_bus(pid), 0);
    struct stat st;
    CHECK(stat(sock, &st) != 0); /* socket removed */

    static char text[1 << 20];
    REQUIRE(read_file(stats_path, text, sizeof text) > 0);
    CHECK(strstr(text, "\"frames\":7,"));
    CHECK(strstr(text, "\"dropped\":1,"));
    CHECK(strstr(text, "\"bad_hellos\":1,"));
    CHECK(strstr(text, "\"late_joins\":1,"));
    CHECK(strstr(text, "\"garbage_disconnects\":1,"));
    CHECK(strstr(text, "\"quanta\":8,"));
    CHECK(strstr(text, "\"name\":\"garbage\",\"roles\":1,\"tx\":1,\"rx\":"));
    const char *gs = strstr(text, "\"name\":\"garbage\"");
    CHECK(gs && strstr(gs, "\"rejected\":101,"));
    const char *as = strstr(text, "\"name\":\"a\"");
    CHECK(as && strstr(as, "\"rejected\":0,"));

    REQUIRE(read_file(trace_path, text, sizeof text) > 0);
    CHECK_EQ(count(text, "\"kind\":\"can_tx\""), 7);
    CHECK_EQ(count(text, "\"kind\":\"can_drop\""), 1);
    CHECK_EQ(count(text, "\"kind\":\"reject\""), 101 + 2);
    CHECK_EQ(count(text, "\"reason\":\"size\""), 1);
    CHECK_EQ(count(text, "\"reason\":\"len\""), 1);
    CHECK_EQ(count(text, "\"reason\":\"id\""), 2);
    CHECK_EQ(count(text, "\"kind\":\"client_join\""), 4);
    CHECK(strstr(text, "{\"t_ns\":135000,\"node\":\"canbus\",\"src\":\"canbus\","
                       "\"kind\":\"can_tx\","
                       "\"start_ns\":0,\"id\":256,\"ext\":false,\"len\":8,"
                       "\"data\":\"0001020304050607\",\"from\":\"b\",\"client\":2}\n"));
    CHECK(strstr(text, "\"kind\":\"client_leave\",\"name\":\"garbage\",\"client\":3,"
                       "\"reason\":\"garbage\""));
    return 0;
}

/* A CLI fault corrupts one client's frames until it is bus-off. */
static int scenario_bus_off(const char *dir)
{
    char sock[256], trace[256];
    snprintf(sock, sizeof sock, "%s/bus2.sock", dir);
    snprintf(trace, sizeof trace, "%s/trace2.jsonl", dir);
    char *argv[] = {(char *)bus_path, "--socket", sock, "--lockstep-clients", "1",
                    "--quantum-us", "1000", "--end-ns", "8000000", "--fault",
                    "corrupt:client=n1,id=0x123", "--trace", trace, "-q", NULL};
    pid_t pid = start_bus(argv, sock);
    client_t obs, n1;
    static struct canbus_rec got[256];
    struct canbus_rec tick;
    int n;
    REQUIRE(join(&obs, sock, "obs", CANBUS_ROLE_CAN) == 0);
    /* A client of the public socket cannot arm a fault: this one would drop every frame. */
    struct canbus_rec arm = {.type = CANBUS_MSG_FAULT, .flags = 1 /* drop */, .id = 0xFFFFFFFF,
                             .t_ns = 0, .aux = 0, .data = {0xFF, 0, 0}};
    sendrecs(&obs, &arm, 1);
    REQUIRE(join(&n1, sock, "n1", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP) == 0);
    REQUIRE(until_tick(&n1, got, 256, &n, &tick) == 0);
    struct canbus_rec q0[] = {frame(0x123, 0, 8, 0), frame(0x124, 0, 8, 0), done(1000000)};
    sendrecs(&n1, q0, 3);
    int errors = 0, frames = 0;
    for (int64_t t = 2000000; t <= 8000000; t += 1000000) {
        REQUIRE(until_tick(&n1, got, 256, &n, &tick) == 0);
        for (int i = 0; i < n; i++) {
            if (got[i].type == CANBUS_MSG_FRAME) {
                frames++;
                continue;
            }
            CHECK_EQ(got[i].type, CANBUS_MSG_ERROR);
            errors++;
            CHECK_EQ(got[i].id, 0x123);
            CHECK_EQ(got[i].data[0], n1.index);
            CHECK_EQ(got[i].data[2], 1);
            CHECK_EQ(got[i].data[3] | got[i].data[4] << 8, 8 * errors);
            CHECK_EQ(got[i].t_ns, 148000 * errors);
            CHECK_EQ(got[i].data[1], errors < 16   ? CANBUS_ERR_ACTIVE
                                     : errors < 32 ? CANBUS_ERR_PASSIVE
                                                   : CANBUS_ERR_BUS_OFF);
        }
        /* After bus-off (4.736 ms) its frames go nowhere. */
        struct canbus_rec q[] = {frame(0x10, 0, 1, t - 1000000), done(t)};
        if (t >= 6000000)
            sendrecs(&n1, q, 2);
        else
            sendrecs(&n1, &q[1], 1);
    }
    CHECK_EQ(errors, 32);
    CHECK_EQ(frames, 0);
    /* The observer saw the same ERROR records and no frame. */
    int obs_errors = 0;
    REQUIRE(until_tick(&obs, got, 256, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_STOP);
    for (int i = 0; i < n; i++) {
        CHECK_EQ(got[i].type, CANBUS_MSG_ERROR);
        obs_errors++;
    }
    CHECK_EQ(obs_errors, 32);
    CHECK_EQ(got[31].data[1], CANBUS_ERR_BUS_OFF);
    close(obs.fd);
    close(n1.fd);
    CHECK_EQ(wait_bus(pid), 0);
    static char text[1 << 16];
    REQUIRE(read_file(trace, text, sizeof text) > 0);
    CHECK(strstr(text, "\"control_record\""));
    CHECK(!strstr(text, "\"fault_armed\""));
    return 0;
}

/* Every FRAME a CAN-only client got until the STOP, identifiers in got[]. */
static int frames_until_stop(const client_t *c, uint32_t *got, int max)
{
    static struct canbus_rec recs[256];
    struct canbus_rec stop;
    int n, k = 0;
    if (until_tick(c, recs, 256, &n, &stop) != 0 || stop.type != CANBUS_MSG_STOP)
        return -1;
    for (int i = 0; i < n; i++)
        if (recs[i].type == CANBUS_MSG_FRAME && k < max)
            got[k++] = recs[i].id;
    return k;
}

/* Faults of the common grammar on the command line: a duplicate, a receiver that misses one
 * identifier, a node's transceiver cut for a spell (named by the node), a target that never
 * joins; what each client receives and what the trace says. */
static int scenario_new_faults(const char *dir)
{
    char sock[256], trace[256];
    snprintf(sock, sizeof sock, "%s/bus4.sock", dir);
    snprintf(trace, sizeof trace, "%s/trace4.jsonl", dir);
    char *argv[] = {(char *)bus_path, "--socket", sock, "--lockstep-clients", "1",
                    "--quantum-us", "1000", "--end-ns", "6000000", "--trace", trace,
                    "--fault", "can_duplicate:fid=dup,at=0,client=a,id=0x100,count=1",
                    "--fault", "rx_drop:fid=rx,at=0,client=c,id=0x200",
                    "--fault", "transceiver_cut:fid=cut,at=2ms,until=4ms,client=node9",
                    "--fault", "can_drop:fid=ghost,at=0,client=nobody", "-q", NULL};
    pid_t pid = start_bus(argv, sock);
    client_t a, b, c, ske, io;
    struct canbus_rec got[64], tick;
    int n;
    REQUIRE(join(&b, sock, "b", CANBUS_ROLE_CAN) == 0);
    REQUIRE(join(&c, sock, "c", CANBUS_ROLE_CAN) == 0);
    REQUIRE(join(&ske, sock, "node9", 0) == 0); /* no controller: the node's io is meant */
    REQUIRE(join(&io, sock, "node9/io", CANBUS_ROLE_CAN) == 0);
    REQUIRE(join(&a, sock, "a", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP) == 0);
    for (int64_t t = 1000000; t <= 6000000; t += 1000000) {
        REQUIRE(until_tick(&a, got, 64, &n, &tick) == 0);
        if (tick.type == CANBUS_MSG_STOP)
            break;
        struct canbus_rec io_frame = frame(0x300 + (uint32_t)(t / 1000000 - 1), 0, 8, 0);
        if (t == 1000000) {
            /* the duplicated 0x100, 0x200 that c must not get, node9/io's 0x300 */
            sendrecs(&io, &io_frame, 1);
            struct canbus_rec q[] = {frame(0x100, 0, 8, 0), frame(0x200, 0, 8, 100000), done(t)};
            sendrecs(&a, q, 3);
        } else if (t == 3000000 || t == 5000000) {
            /* [2, 3 ms): node9/io is cut, both ways; [4, 5 ms): it is back */
            sendrecs(&io, &io_frame, 1);
            struct canbus_rec q[] = {frame(0x1FF + (uint32_t)(t / 1000000 - 1), 0, 8, t - 1000000),
                                     done(t)};
            sendrecs(&a, q, 2);
        } else {
            struct canbus_rec d = done(t);
            sendrecs(&a, &d, 1);
        }
    }
    uint32_t ids[32];
    /* b: everything, the duplicate twice */
    static const uint32_t want_b[] = {0x100, 0x100, 0x200, 0x300, 0x201, 0x203, 0x304};
    CHECK_EQ(frames_until_stop(&b, ids, 32), 7);
    for (int i = 0; i < 7; i++)
        CHECK_EQ(ids[i], want_b[i]);
    /* c: not 0x200 (rx_drop matches one identifier: 0x201 and 0x203 come) */
    static const uint32_t want_c[] = {0x100, 0x100, 0x300, 0x201, 0x203, 0x304};
    CHECK_EQ(frames_until_stop(&c, ids, 32), 6);
    for (int i = 0; i < 6; i++)
        CHECK_EQ(ids[i], want_c[i]);
    /* node9/io: nothing during its cut (0x201), its own 0x302 never went out */
    static const uint32_t want_io[] = {0x100, 0x100, 0x200, 0x203};
    CHECK_EQ(frames_until_stop(&io, ids, 32), 4);
    for (int i = 0; i < 4; i++)
        CHECK_EQ(ids[i], want_io[i]);
    close(a.fd);
    close(b.fd);
    close(c.fd);
    close(ske.fd);
    close(io.fd);
    CHECK_EQ(wait_bus(pid), 0);

    static char text[1 << 16];
    REQUIRE(read_file(trace, text, sizeof text) > 0);
    CHECK_EQ(count(text, "\"kind\":\"fault\""), 5);
    CHECK(strstr(text, "{\"t_ns\":0,\"node\":\"canbus\",\"src\":\"canbus\",\"kind\":\"fault\","
                       "\"fid\":\"dup\",\"class\":\"can_duplicate\",\"target\":\"a\","
                       "\"state\":\"applied\",\"detail\":\"duplicated 0x100 from a\"}\n"));
    CHECK(strstr(text, "\"kind\":\"fault\",\"fid\":\"rx\",\"class\":\"rx_drop\","
                       "\"target\":\"c\",\"state\":\"applied\""));
    CHECK(strstr(text, "{\"t_ns\":2000000,\"node\":\"canbus\",\"src\":\"canbus\",\"kind\":\"fault\","
                       "\"fid\":\"cut\",\"class\":\"transceiver_cut\",\"target\":\"node9/io\","
                       "\"state\":\"applied\""));
    CHECK(strstr(text, "{\"t_ns\":4000000,\"node\":\"canbus\",\"src\":\"canbus\",\"kind\":\"fault\","
                       "\"fid\":\"cut\",\"class\":\"transceiver_cut\",\"target\":\"node9/io\","
                       "\"state\":\"cleared\",\"detail\":\"spell ended after 2 frame(s)\"}\n"));
    CHECK(strstr(text, "\"kind\":\"fault\",\"fid\":\"ghost\",\"class\":\"can_drop\","
                       "\"target\":\"nobody\",\"state\":\"refused\","
                       "\"detail\":\"no CAN client 'nobody' joined\"}\n"));
    CHECK_EQ(count(text, "\"duplicate\":true,\"fid\":\"dup\""), 1);
    CHECK_EQ(count(text, "\"kind\":\"can_rx_drop\""), 2);
    CHECK(strstr(text, "\"kind\":\"can_rx_drop\",\"start_ns\":270000,\"id\":512,"
                       "\"ext\":false,\"len\":8,\"from\":\"a\",\"client\":4,\"to\":\"c\","
                       "\"to_client\":1,\"fid\":\"rx\"}\n"));
    CHECK(strstr(text, "\"kind\":\"can_drop\",\"id\":770,\"ext\":false,\"len\":8,"
                       "\"from\":\"node9/io\",\"client\":3,\"reason\":\"fault\",\"fid\":\"cut\"}"));
    return 0;
}

/* A bus that knows its clients (--client): hellos checked against the declarations, a name
 * taken refused until its holder has gone (an io partition restarted), an undeclared client
 * listen-only (it gets the frames; its frames, STOP and FAULT records do nothing), the
 * launcher's STOP on the control channel; the statistics name them all. */
static int scenario_admission(const char *dir)
{
    char sock[256], stats_path[256], trace[256];
    snprintf(sock, sizeof sock, "%s/bus5.sock", dir);
    snprintf(stats_path, sizeof stats_path, "%s/stats5.json", dir);
    snprintf(trace, sizeof trace, "%s/trace5.jsonl", dir);
    int ctl[2];
    char ctl_fd[16];
    REQUIRE(control_pair(ctl, ctl_fd, sizeof ctl_fd) == 0);
    char *argv[] = {(char *)bus_path, "--socket", sock, "--lockstep-clients", "1",
                    "--quantum-us", "1000", "--trace", trace, "--stats", stats_path,
                    "--control-fd", ctl_fd, "--client", "n1:can+lockstep:1",
                    "--client", "n1/io:can:1", "--client", "n2/io:can:2", "-q", NULL};
    pid_t pid = start_bus(argv, sock);
    close(ctl[1]);
    /* Node 1's process is this test (its clients: it or its children); node 2's is the bus
     * itself, so that this test is nobody of node 2. */
    struct canbus_rec procs[] = {{.type = CANBUS_MSG_PROCESS, .id = 1, .t_ns = getpid()},
                                 {.type = CANBUS_MSG_PROCESS, .id = 2, .t_ns = pid}};
    CHECK(send(ctl[0], procs, sizeof procs, 0) == (ssize_t)sizeof procs);
    client_t n1, io, io2, tool;
    struct canbus_rec got[64], tick;
    int n;
    CHECK_EQ(refused_hello(sock, "n1/io", CANBUS_ROLE_LOCKSTEP, 1), CANBUS_STOP_REFUSED);
    CHECK_EQ(refused_hello(sock, "n1/io", CANBUS_ROLE_CAN, 2), CANBUS_STOP_REFUSED);
    CHECK_EQ(refused_hello(sock, "spy", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP, 0),
             CANBUS_STOP_REFUSED);
    CHECK_EQ(refused_hello(sock, "spy", CANBUS_ROLE_CAN, 7), CANBUS_STOP_REFUSED);
    CHECK_EQ(refused_hello(sock, "0123456789abcdef0123456789abcdef", CANBUS_ROLE_CAN, 0),
             CANBUS_STOP_BAD_HELLO);
    CHECK_EQ(refused_hello(sock, "bad\nname", CANBUS_ROLE_CAN, 0), CANBUS_STOP_BAD_HELLO);
    CHECK_EQ(refused_hello(sock, "n2/io", CANBUS_ROLE_CAN, 2), CANBUS_STOP_REFUSED);
    REQUIRE(join_node(&io, sock, "n1/io", CANBUS_ROLE_CAN, 1) == 0);
    CHECK_EQ(io.wl.flags, 0);
    CHECK_EQ(refused_hello(sock, "n1/io", CANBUS_ROLE_CAN, 1), CANBUS_STOP_REFUSED);
    close(io.fd); /* io restarted: its successor takes the name */
    REQUIRE(join_node(&io2, sock, "n1/io", CANBUS_ROLE_CAN, 1) == 0);
    REQUIRE(join_node(&tool, sock, "python-can", CANBUS_ROLE_CAN, 0) == 0);
    CHECK_EQ(tool.wl.flags, CANBUS_WELCOME_LISTEN_ONLY);
    REQUIRE(join_node(&n1, sock, "n1", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP, 1) == 0);
    REQUIRE(until_tick(&n1, got, 64, &n, &tick) == 0);
    /* The tool tries a frame of its own, a fault that would drop every frame, a STOP. */
    struct canbus_rec arm = {.type = CANBUS_MSG_FAULT, .flags = 1 /* drop */, .id = 0xFFFFFFFF,
                             .data = {0xFF, 0, 0}};
    struct canbus_rec stop = {.type = CANBUS_MSG_STOP, .id = CANBUS_STOP_REQUESTED};
    struct canbus_rec evil[] = {frame(0x001, 0, 8, 0), arm, stop};
    sendrecs(&tool, evil, 3);
    struct canbus_rec q0[] = {frame(0x123, 0, 8, 0), done(1000000)};
    sendrecs(&n1, q0, 2);
    REQUIRE(until_tick(&n1, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_TICK); /* the tool's STOP stopped nothing */
    struct canbus_rec d2 = done(2000000);
    sendrecs(&n1, &d2, 1);
    REQUIRE(until_tick(&n1, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_TICK);
    /* The launcher ends the run: the bus stops waiting for n1's DONE (none is sent: the bus
     * may have closed n1's socket by then). */
    CHECK(send(ctl[0], &stop, sizeof stop, 0) == (ssize_t)sizeof stop);
    REQUIRE(until_tick(&n1, got, 64, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_STOP);
    CHECK_EQ(tick.id, CANBUS_STOP_REQUESTED);
    uint32_t ids[8];
    CHECK_EQ(frames_until_stop(&io2, ids, 8), 1); /* the 0x123 alone: nothing was dropped */
    CHECK_EQ(frames_until_stop(&tool, ids, 8), 1);
    CHECK_EQ(ids[0], 0x123);
    close(n1.fd);
    close(io2.fd);
    close(tool.fd);
    close(ctl[0]);
    CHECK_EQ(wait_bus(pid), 0);
    static char text[1 << 16];
    REQUIRE(read_file(stats_path, text, sizeof text) > 0);
    static const char *const stats_has[] = {
        "\"frames\":1,", "\"bad_hellos\":2,", "\"refused_hellos\":6,",
        "\"refused_records\":3,", "\"stopped_by\":\"launcher\"", "\"name\":\"python-can\"",
        "\"listen_only\":true", "refused: not_as_declared\"}", "refused: undeclared_lockstep\"}",
        "refused: unknown_node\"}", "refused: duplicate_name\"}", "listen-only, pid ",
        "refused: not_its_process\"}",
        "refused 1 FRAME, 1 STOP, 1 FAULT\"}"};
    for (size_t i = 0; i < sizeof stats_has / sizeof *stats_has; i++)
        if (!strstr(text, stats_has[i])) {
            fprintf(stderr, "stats5.json lacks %s\n", stats_has[i]);
            unit_failures++;
        }
    CHECK_EQ(count(text, "{\"what\":\"can_client\",\"detail\":"), 9);
    REQUIRE(read_file(trace, text, sizeof text) > 0);
    CHECK(strstr(text, "\"kind\":\"stop_request\",\"by\":\"launcher\"}"));
    CHECK_EQ(count(text, "\"reason\":\"listen_only\""), 3);
    CHECK_EQ(count(text, "\"kind\":\"can_tx\""), 1);
    return 0;
}

/* SIGTERM: STOP(SIGNAL) to clients, exit 0. */
static int scenario_signal(const char *dir)
{
    char sock[256], stats_path[256];
    snprintf(sock, sizeof sock, "%s/bus3.sock", dir);
    snprintf(stats_path, sizeof stats_path, "%s/stats3.json", dir);
    char *argv[] = {(char *)bus_path, "--socket", sock, "--lockstep-clients", "1",
                    "--stats", stats_path, "-q", NULL};
    pid_t pid = start_bus(argv, sock);
    client_t c;
    struct canbus_rec got[8], tick;
    int n;
    REQUIRE(join(&c, sock, "c", CANBUS_ROLE_LOCKSTEP) == 0);
    REQUIRE(until_tick(&c, got, 8, &n, &tick) == 0);
    kill(pid, SIGTERM);
    REQUIRE(until_tick(&c, got, 8, &n, &tick) == 0);
    CHECK_EQ(tick.type, CANBUS_MSG_STOP);
    CHECK_EQ(tick.id, CANBUS_STOP_SIGNAL);
    close(c.fd);
    CHECK_EQ(wait_bus(pid), 0);
    static char text[1 << 16];
    CHECK(read_file(stats_path, text, sizeof text) > 0 && strstr(text, "\"stop\":\"signal\""));
    CHECK(strstr(text, "\"stopped_by\":\"signal\",\"refusals\":[]}"));
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_canbus_socket PATH-TO-ima-canbus\n");
        return 2;
    }
    bus_path = argv[1];
    signal(SIGPIPE, SIG_IGN);
    char dir[] = "/tmp/test_canbus_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    char t1[300], t2[300];
    snprintf(t1, sizeof t1, "%s/trace1.jsonl", dir);
    snprintf(t2, sizeof t2, "%s/trace2.jsonl", dir);
    scenario_main(dir, t1);
    scenario_main(dir, t2);
    /* Same inputs, same trace: the bus is deterministic in emulated time (nodes/README.md). */
    static char a[1 << 20], b[1 << 20];
    int na = read_file(t1, a, sizeof a), nb = read_file(t2, b, sizeof b);
    CHECK(na > 0 && na == nb && memcmp(a, b, (size_t)na) == 0);
    scenario_bus_off(dir);
    scenario_new_faults(dir);
    scenario_admission(dir);
    scenario_signal(dir);
    if (!unit_failures) {
        char cmd[400];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", dir);
        printf("test_canbus_socket: ok\n");
    } else
        fprintf(stderr, "test_canbus_socket: %d check(s) failed (files in %s)\n", unit_failures, dir);
    return unit_failures ? 1 : 0;
}
