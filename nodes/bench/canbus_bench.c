/* SPDX-License-Identifier: Apache-2.0 */
/* Throughput of ima-canbus: N forked LOCKSTEP clients each send K frames per quantum (one
 * datagram with the DONE) and receive all the others'; prints one JSON object. */
#include "canbus/proto.h"

#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct {
    uint64_t rx, order_errors;
    int64_t first_tick_wall, stop_wall;
    int ok;
} result_t;

static int64_t wall_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Frame j of client c: ids spread over both formats, lengths 0..8. */
static void make_frame(struct canbus_rec *r, int c, int j, int64_t t)
{
    memset(r, 0, sizeof *r);
    r->type = CANBUS_MSG_FRAME;
    r->len = (uint8_t)((j + c) % 9);
    if (j % 4 == 3) {
        r->flags = CANBUS_FRAME_EFF;
        r->id = (uint32_t)(0x18000000u + (uint32_t)c * 0x10000u + (uint32_t)j);
    } else
        r->id = (uint32_t)(0x100 + c * 0x80 + (j % 0x80));
    r->t_ns = t;
    for (int i = 0; i < r->len; i++)
        r->data[i] = (uint8_t)(j + i);
}

static double avg_bits(int clients, int k)
{
    double sum = 0;
    struct canbus_rec r;
    for (int c = 0; c < clients; c++)
        for (int j = 0; j < k; j++) {
            make_frame(&r, c, j, 0);
            sum += canbus_frame_bits(r.flags & CANBUS_FRAME_EFF, r.len);
        }
    return sum / (clients * k);
}

static int client_main(const char *sock, int c, int k, int out_fd)
{
    result_t res = {0};
    int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (strlen(sock) >= sizeof sa.sun_path)
        return 1;
    memcpy(sa.sun_path, sock, strlen(sock) + 1);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa))
        return 1;
    struct canbus_hello h = {.magic = CANBUS_MAGIC, .version = CANBUS_VERSION,
                             .roles = CANBUS_ROLE_CAN | CANBUS_ROLE_LOCKSTEP};
    snprintf(h.name, sizeof h.name, "bench%d", c);
    struct canbus_welcome wl;
    if (send(fd, &h, sizeof h, 0) != sizeof h || recv(fd, &wl, sizeof wl, 0) != sizeof wl)
        return 1;
    static struct canbus_rec in[CANBUS_MAX_RECS], out[CANBUS_MAX_RECS];
    int64_t last_t = 0;
    for (;;) {
        ssize_t n = recv(fd, in, sizeof in, 0);
        if (n <= 0)
            break;
        for (ssize_t i = 0; i < n / 32; i++) {
            const struct canbus_rec *r = &in[i];
            if (r->type == CANBUS_MSG_FRAME) {
                res.rx++;
                if (r->t_ns < last_t)
                    res.order_errors++;
                last_t = r->t_ns;
            } else if (r->type == CANBUS_MSG_TICK) {
                if (!res.first_tick_wall)
                    res.first_tick_wall = wall_ns();
                int64_t t0 = r->aux, span = r->t_ns - r->aux;
                int m = 0;
                for (int j = 0; j < k && m < CANBUS_MAX_RECS - 1; j++)
                    make_frame(&out[m++], c, j, t0 + span * j / k);
                out[m++] = (struct canbus_rec){.type = CANBUS_MSG_DONE, .t_ns = r->t_ns};
                if (send(fd, out, (size_t)m * sizeof *out, MSG_NOSIGNAL) < 0)
                    goto end;
            } else if (r->type == CANBUS_MSG_STOP) {
                res.ok = r->id == CANBUS_STOP_END;
                goto end;
            }
        }
    }
end:
    res.stop_wall = wall_ns();
    close(fd);
    return write(out_fd, &res, sizeof res) == sizeof res ? 0 : 1;
}

static double stats_number(const char *text, const char *key)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(text, pat);
    return p ? strtod(p + strlen(pat), NULL) : -1;
}

int main(int argc, char **argv)
{
    char self[PATH_MAX], bus[PATH_MAX + 16];
    ssize_t sl = readlink("/proc/self/exe", self, sizeof self - 1);
    self[sl > 0 ? sl : 0] = '\0';
    snprintf(bus, sizeof bus, "%s/ima-canbus", dirname(self));
    long frames = 1000000, k = 0, quantum_us = 20000, bitrate = 1000000, clients = 4;
    const char *trace = NULL;
    static const struct option lo[] = {
        {"bus", required_argument, NULL, 'b'},     {"frames", required_argument, NULL, 'n'},
        {"per-quantum", required_argument, NULL, 'k'}, {"quantum-us", required_argument, NULL, 'q'},
        {"bitrate", required_argument, NULL, 'r'}, {"clients", required_argument, NULL, 'c'},
        {"trace", required_argument, NULL, 't'},   {0},
    };
    int opt;
    while ((opt = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        switch (opt) {
        case 'b': snprintf(bus, sizeof bus, "%s", optarg); break;
        case 'n': frames = strtol(optarg, NULL, 0); break;
        case 'k': k = strtol(optarg, NULL, 0); break;
        case 'q': quantum_us = strtol(optarg, NULL, 0); break;
        case 'r': bitrate = strtol(optarg, NULL, 0); break;
        case 'c': clients = strtol(optarg, NULL, 0); break;
        case 't': trace = optarg; break;
        default:
            fprintf(stderr, "usage: ima-canbus-bench [--frames N] [--clients N] [--per-quantum K]"
                            " [--quantum-us US] [--bitrate B] [--trace FILE] [--bus PATH]\n");
            return 2;
        }
    }
    if (clients < 2 || clients > 64 || frames < 1 || quantum_us < 100 || bitrate < 1000) {
        fprintf(stderr, "ima-canbus-bench: bad arguments\n");
        return 2;
    }
    int64_t quantum_ns = quantum_us * 1000;
    /* By default fill about 80 % of the wire so that no backlog builds up. */
    if (k <= 0) {
        double bits = (double)quantum_ns * (double)bitrate / 1e9;
        k = 1;
        while (k < CANBUS_MAX_RECS - 1 &&
               (k + 1) * clients * avg_bits((int)clients, (int)k + 1) <= 0.8 * bits)
            k++;
    }
    long per_quantum = k * clients;
    long quanta = (frames + per_quantum - 1) / per_quantum + 2; /* the last two carry nothing */
    int64_t end_ns = quanta * quantum_ns;

    char dir[] = "/tmp/canbus_bench_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    char sock[100], stats[128], endarg[32], qarg[32], rarg[32], narg[32];
    snprintf(sock, sizeof sock, "%s/bus.sock", dir);
    snprintf(stats, sizeof stats, "%s/stats.json", dir);
    snprintf(endarg, sizeof endarg, "%" PRId64, end_ns);
    snprintf(qarg, sizeof qarg, "%ld", quantum_us);
    snprintf(rarg, sizeof rarg, "%ld", bitrate);
    snprintf(narg, sizeof narg, "%ld", clients);
    pid_t bus_pid = fork();
    if (bus_pid == 0) {
        char *av[20] = {bus, "--socket", sock, "--lockstep-clients", narg, "--quantum-us", qarg,
                        "--bitrate", rarg, "--end-ns", endarg, "--stats", stats, "-q"};
        int i = 14;
        if (trace) {
            av[i++] = "--trace";
            av[i++] = (char *)trace;
        }
        av[i] = NULL;
        execv(bus, av);
        perror(bus);
        _exit(127);
    }
    for (int i = 0; i < 500; i++) {
        struct stat st;
        if (stat(sock, &st) == 0)
            break;
        struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
    }
    int pfd[2];
    if (pipe(pfd))
        return 1;
    pid_t kids[64];
    for (int c = 0; c < clients; c++) {
        kids[c] = fork();
        if (kids[c] == 0) {
            close(pfd[0]);
            _exit(client_main(sock, c, (int)k, pfd[1]));
        }
    }
    close(pfd[1]);
    result_t res[64];
    int got = 0;
    uint64_t rx = 0, order_errors = 0;
    int64_t t0 = INT64_MAX, t1 = 0;
    int ok = 1;
    while (got < clients && read(pfd[0], &res[got], sizeof res[got]) == sizeof res[got]) {
        rx += res[got].rx;
        order_errors += res[got].order_errors;
        ok &= res[got].ok;
        if (res[got].first_tick_wall && res[got].first_tick_wall < t0)
            t0 = res[got].first_tick_wall;
        if (res[got].stop_wall > t1)
            t1 = res[got].stop_wall;
        got++;
    }
    for (int c = 0; c < clients; c++)
        waitpid(kids[c], NULL, 0);
    int st;
    waitpid(bus_pid, &st, 0);
    ok &= got == clients && WIFEXITED(st) && WEXITSTATUS(st) == 0 && order_errors == 0;

    char text[1 << 16] = "";
    FILE *f = fopen(stats, "r");
    if (f) {
        size_t n = fread(text, 1, sizeof text - 1, f);
        text[n] = '\0';
        fclose(f);
    }
    /* Every client receives every frame but its own. */
    uint64_t wire_frames = rx / (uint64_t)(clients - 1);
    /* A frame still on the wire at the end is counted by the bus but not delivered. */
    double bus_frames = stats_number(text, "frames");
    ok &= rx % (uint64_t)(clients - 1) == 0 && bus_frames >= (double)wire_frames &&
          bus_frames <= (double)wire_frames + 1 &&
          wire_frames >= (uint64_t)((quanta - 2) * per_quantum);
    double wall = t1 > t0 ? (double)(t1 - t0) / 1e9 : 0;
    printf("{\"canbus_frames_per_s\": %.0f, \"clients\": %ld, \"frames\": %" PRIu64
           ", \"wall_s\": %.4f, \"frames_per_quantum\": %ld, \"quanta\": %ld, \"quantum_us\": %ld,"
           " \"bitrate\": %ld, \"bus_load\": %.4f, \"trace\": %s, \"ok\": %s}\n",
           wall > 0 ? (double)wire_frames / wall : 0.0, clients, wire_frames, wall, per_quantum,
           quanta, quantum_us, bitrate, stats_number(text, "load"), trace ? "true" : "false",
           ok ? "true" : "false");
    unlink(stats);
    rmdir(dir);
    return ok ? 0 : 1;
}
