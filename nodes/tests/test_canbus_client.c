/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the CAN bus client library (include/canbus/client.h) against a scripted bus
 * in a child process: refused and broken joins, what it does with records it cannot take,
 * its receive queue when nobody reads, batching, lockstep waits and the bus's end. */
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include "canbus/client.h"
#include "canbus/proto.h"
#include "canbus_test.h"

/* A join the test needs: without it the rest of the case means nothing. */
#define REQUIRE_OK(call)                                                                      \
    do {                                                                                      \
        if ((call) != CANBUS_OK) {                                                            \
            fprintf(stderr, "%s:%d: %s failed: %s\n", __FILE__, __LINE__, #call, err);       \
            unit_failures++;                                                                  \
            return;                                                                           \
        }                                                                                     \
    } while (0)

static char dir[] = "/tmp/canbus_client.XXXXXX";
static char sock[64];

typedef void (*bus_script_t)(int conn);

/* A listening socket at `sock` whose one connection runs `script` in a child process. */
static pid_t fake_bus(bus_script_t script)
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", sock);
    unlink(sock);
    int l = socket(AF_UNIX, SOCK_SEQPACKET, 0);
    if (l < 0 || bind(l, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(l, 1) != 0) {
        perror("fake bus");
        exit(1);
    }
    pid_t pid = fork();
    if (pid == 0) {
        int c = accept(l, NULL, NULL);
        struct canbus_hello h;
        if (c < 0 || recv(c, &h, sizeof h, 0) != (ssize_t)sizeof h || h.magic != CANBUS_MAGIC)
            _exit(3);
        script(c);
        close(c);
        _exit(0);
    }
    close(l);
    return pid;
}

static int bus_status(pid_t pid)
{
    int st;
    waitpid(pid, &st, 0);
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

static void welcome(int c, uint32_t flags)
{
    struct canbus_welcome w = {.magic = CANBUS_MAGIC, .version = CANBUS_VERSION, .client = 3,
                               .bitrate = 500000, .flags = flags, .quantum_ns = 1000000,
                               .t_ns = 7000000, .end_ns = -1};
    send(c, &w, sizeof w, 0);
}

static struct canbus_rec rec(uint8_t type, uint32_t id, uint8_t len, int64_t t)
{
    return (struct canbus_rec){.type = type, .id = id, .len = len, .t_ns = t};
}

/* Waits for the client's next datagram (so that the script's sends are not reordered with
 * what the test does in between); returns its records. */
static int next_datagram(int c, struct canbus_rec *got, int max)
{
    ssize_t n = recv(c, got, (size_t)max * sizeof *got, 0);
    return n < 0 ? -1 : (int)(n / (ssize_t)sizeof *got);
}

/* ---- joining ---------------------------------------------------------------------------- */

static void script_refuse(int c)
{
    struct canbus_rec r = rec(CANBUS_MSG_STOP, CANBUS_STOP_FULL, 0, 0);
    send(c, &r, sizeof r, 0);
}

static void script_garbage(int c) { send(c, "hello?", 6, 0); }

static void test_join_failures(void)
{
    canbus_client_t c;
    char err[256];
    char longpath[200];
    memset(longpath, 'x', sizeof longpath - 1);
    longpath[sizeof longpath - 1] = '\0';
    CHECK_EQ(canbus_client_connect(&c, longpath, "n", CANBUS_ROLE_CAN, 0, err, sizeof err),
             -ENAMETOOLONG);
    CHECK(strstr(err, "longer than") != NULL);
    CHECK_EQ(canbus_client_connect(&c, NULL, "n", CANBUS_ROLE_CAN, 0, err, sizeof err),
             -ENAMETOOLONG);
    unlink(sock);
    CHECK_EQ(canbus_client_connect(&c, sock, "n", CANBUS_ROLE_CAN, 0, err, sizeof err), -ENOENT);
    CHECK(strstr(err, "cannot connect to the CAN bus at") != NULL);

    pid_t bus = fake_bus(script_refuse);
    CHECK_EQ(canbus_client_connect(&c, sock, "n", CANBUS_ROLE_CAN, 0, err, sizeof err),
             -ECONNREFUSED);
    char want[64];
    snprintf(want, sizeof want, "refused us (reason %u)", (unsigned)CANBUS_STOP_FULL);
    CHECK(strstr(err, want) != NULL);
    CHECK_EQ(bus_status(bus), 0);

    bus = fake_bus(script_garbage);
    CHECK_EQ(canbus_client_connect(&c, sock, NULL, CANBUS_ROLE_CAN, 0, err, sizeof err), -EPROTO);
    CHECK(strstr(err, "did not answer with a welcome") != NULL);
    CHECK_EQ(bus_status(bus), 0);
}

/* ---- records the client cannot take ------------------------------------------------------ */

static void script_bad_records(int c)
{
    welcome(c, 0);
    struct canbus_rec got[4];
    next_datagram(c, got, 4); /* the client is ready */
    send(c, "odd", 3, 0); /* not a whole record */
    struct canbus_rec mixed[4] = {rec(CANBUS_MSG_FRAME, 0x100, 9, 1), /* len > 8 */
                                  rec(77, 0, 0, 2), /* unknown type */
                                  rec(CANBUS_MSG_ERROR, 0x200, 0, 3),
                                  rec(CANBUS_MSG_FRAME, 0x300, 2, 4)};
    send(c, mixed, sizeof mixed, 0);
    next_datagram(c, got, 4);
}

static void test_bad_records_are_counted_not_taken(void)
{
    pid_t bus = fake_bus(script_bad_records);
    canbus_client_t c;
    char err[256];
    REQUIRE_OK(canbus_client_connect(&c, sock, "n", CANBUS_ROLE_CAN, 2, err, sizeof err));
    CHECK_EQ(c.index, 3);
    CHECK_EQ(c.bitrate, 500000);
    CHECK_EQ(c.granted_ns, 7000000);
    CHECK_EQ(c.end_ns, -1);
    struct canbus_rec r;
    CHECK_EQ(canbus_client_recv(&c, &r), 0); /* nothing yet */
    CHECK_EQ(canbus_client_request_stop(&c), 0); /* "ready" */
    int n = 0;
    struct canbus_rec got[2];
    for (int tries = 0; n < 2 && tries < 2000; tries++) {
        int rc = canbus_client_recv(&c, &r);
        if (rc == 1)
            got[n++] = r;
        else
            usleep(1000);
    }
    CHECK_EQ(n, 2);
    CHECK_EQ(got[0].type, CANBUS_MSG_ERROR);
    CHECK_EQ(got[1].id, 0x300);
    CHECK_EQ(c.rejected, 3);
    canbus_client_close(&c);
    CHECK_EQ(c.fd, -1);
    canbus_client_close(&c); /* twice is harmless */
    CHECK_EQ(bus_status(bus), 0);
}

/* ---- nobody reads --------------------------------------------------------------------------- */

static void script_flood(int c)
{
    welcome(c, 0);
    struct canbus_rec got[4];
    next_datagram(c, got, 4);
    struct canbus_rec batch[64];
    for (int k = 0; k < (CANBUS_IN_RECS + 100) / 64 + 1; k++) {
        for (int i = 0; i < 64; i++)
            batch[i] = rec(CANBUS_MSG_FRAME, (uint32_t)(k * 64 + i) & 0x7FF, 1, k * 64 + i);
        send(c, batch, sizeof batch, 0);
    }
    struct canbus_rec stop = rec(CANBUS_MSG_STOP, CANBUS_STOP_END, 0, 0);
    send(c, &stop, sizeof stop, 0);
}

static void test_a_full_receive_queue_keeps_the_newest(void)
{
    pid_t bus = fake_bus(script_flood);
    canbus_client_t c;
    char err[256];
    REQUIRE_OK(canbus_client_connect(&c, sock, "n", CANBUS_ROLE_CAN, 0, err, sizeof err));
    CHECK_EQ(canbus_client_request_stop(&c), 0);
    /* The lockstep wait reads everything until the STOP, taking no frame. */
    CHECK_EQ(canbus_client_done_wait(&c), CANBUS_STOPPED);
    CHECK_EQ(c.stop_reason, CANBUS_STOP_END);
    int sent = ((CANBUS_IN_RECS + 100) / 64 + 1) * 64;
    CHECK_EQ(c.overflowed, sent - CANBUS_IN_RECS);
    struct canbus_rec r;
    CHECK_EQ(canbus_client_recv(&c, &r), 1);
    CHECK_EQ(r.t_ns, sent - CANBUS_IN_RECS); /* the oldest kept */
    int left = 1;
    while (canbus_client_recv(&c, &r) == 1)
        left++;
    CHECK_EQ(left, CANBUS_IN_RECS);
    CHECK_EQ(r.t_ns, sent - 1);
    CHECK_EQ(canbus_client_recv(&c, &r), -ESHUTDOWN);
    CHECK_EQ(canbus_client_done_wait(&c), CANBUS_STOPPED);
    canbus_client_close(&c);
    CHECK_EQ(bus_status(bus), 0);
}

/* ---- sending and the lockstep -------------------------------------------------------------- */

static void script_lockstep(int c)
{
    welcome(c, CANBUS_WELCOME_REALTIME);
    struct canbus_rec got[CANBUS_MAX_RECS];
    int frames = 0, n;
    /* 300 frames arrive in two datagrams (the client batches 256 at most), then a DONE-less
     * wait before the first TICK. */
    while (frames < 300 && (n = next_datagram(c, got, CANBUS_MAX_RECS)) > 0)
        frames += n;
    struct canbus_rec tick = rec(CANBUS_MSG_TICK, 0, 0, 9000000);
    tick.aux = 8000000;
    tick.data[0] = 0x10; /* 16 ns late */
    send(c, &tick, sizeof tick, 0);
    /* The client's DONE for 9 ms, then the bus closes without a STOP. */
    n = next_datagram(c, got, CANBUS_MAX_RECS);
    _exit(frames == 300 && n == 1 && got[0].type == CANBUS_MSG_DONE && got[0].t_ns == 9000000
              ? 0
              : 4);
}

static void test_batching_and_the_lockstep(void)
{
    pid_t bus = fake_bus(script_lockstep);
    canbus_client_t c;
    char err[256];
    REQUIRE_OK(canbus_client_connect(&c, sock, "io", CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP, 1,
                                     err, sizeof err));
    uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    CHECK_EQ(canbus_client_send(&c, 0x800, false, data, 8, 0), -EINVAL); /* 11-bit id */
    CHECK_EQ(canbus_client_send(&c, 0x20000000, true, data, 8, 0), -EINVAL);
    CHECK_EQ(canbus_client_send(&c, 0x100, false, data, 9, 0), -EINVAL);
    for (int i = 0; i < 300; i++)
        CHECK_EQ(canbus_client_send(&c, 0x1ABCDEF, true, i % 2 ? data : NULL, (uint8_t)(i % 2 ? 8 : 0),
                                    i),
                 0);
    CHECK_EQ(c.out_n, 300 - CANBUS_OUT_RECS); /* the first 256 went at once */
    /* No TICK yet: nothing to report done; the frames go, then the wait for the first TICK. */
    CHECK_EQ(canbus_client_done_wait(&c), CANBUS_OK);
    CHECK_EQ(c.granted_ns, 9000000);
    CHECK_EQ(c.tick_start_ns, 8000000);
    CHECK_EQ(c.tick_late_ns, 16);
    CHECK(c.tick_mono_ns > 0);
    /* Its DONE for 9 ms; the bus then goes away without a STOP: the run is over all the same. */
    CHECK_EQ(canbus_client_done_wait(&c), CANBUS_STOPPED);
    struct canbus_rec r;
    CHECK_EQ(canbus_client_recv(&c, &r), -ESHUTDOWN);
    /* Sending to a bus that has gone is an error the caller sees. */
    CHECK_EQ(canbus_client_send(&c, 0x100, false, data, 1, 0), 0);
    CHECK_EQ(canbus_client_flush(&c), -EPIPE);
    CHECK_EQ(canbus_client_flush(&c), 0); /* nothing left to send */
    canbus_client_close(&c);
    CHECK_EQ(bus_status(bus), 0);
}

int main(void)
{
    signal(SIGPIPE, SIG_IGN);
    if (!mkdtemp(dir))
        return 1;
    snprintf(sock, sizeof sock, "%s/bus.sock", dir);
    test_join_failures();
    test_bad_records_are_counted_not_taken();
    test_a_full_receive_queue_keeps_the_newest();
    test_batching_and_the_lockstep();
    unlink(sock);
    rmdir(dir);
    if (unit_failures) {
        fprintf(stderr, "%d check(s) failed\n", unit_failures);
        return 1;
    }
    printf("ok   test_canbus_client\n");
    return 0;
}
