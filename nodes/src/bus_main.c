/* SPDX-License-Identifier: Apache-2.0 */
/* The ima-canbus command line: options, signals, exit status. */
#include "canbus__bus.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

/* Exit status: 0 the run ended (end time, a client's STOP, SIGINT/SIGTERM), 1 the bus
 * failed (socket, trace or stats file, memory), 2 bad command line. */
enum { EXIT_USAGE = 2 };

static void usage(FILE *f)
{
    fputs("usage: ima-canbus --socket PATH [options]\n"
          "  --bitrate BIT/S          bit rate (1000000)\n"
          "  --quantum-us US          lockstep quantum (5000)\n"
          "  --lockstep-clients N     LOCKSTEP clients to wait for before T=0 (0: free-running)\n"
          "  --duration SECONDS | --end-ns NS   end of the run (none: until STOP or a signal)\n"
          "  --realtime               pace quanta by CLOCK_MONOTONIC\n"
          "  --pace FACTOR            lockstep, but no faster than FACTOR x the wall clock\n"
          "                           (a live view: the nodes' time stays emulated)\n"
          "  --trace FILE             JSON-lines trace ('-' for stdout)\n"
          "  --stats FILE             JSON statistics at exit ('-' for stdout)\n"
          "  --max-clients N          connected clients at most (64)\n"
          "  --fault SPEC             CLASS:fid=ID,at=TIME[,until=TIME][,period=TIME,on=TIME][,KEY=VALUE]\n"
          "                           (faultinject/README.md; older KIND:KEY=VALUE too); repeatable\n"
          "  --control-fd N           the launcher's control channel: an inherited SOCK_SEQPACKET\n"
          "                           socket whose FAULT records arm faults and STOP ends the run\n"
          "  --client NAME:ROLES:NODE a client of the run (ROLES: can, lockstep, own joined by +);\n"
          "                           repeatable. With any, other names join listen-only\n"
"  --kill-node N@SECONDS    kill every client of node N (hello.node) at that time; repeatable\n"
          "  --hang-node N@SECONDS    freeze them instead (SIGSTOP): a hung processor; repeatable\n"
          "  --client-order A,B,...   client indices by name (deterministic for racy joins)\n"
          "  --bus-off-recovery       clients recover from bus-off after 128 x 11 bit times\n"
          "  --max-rejects N          disconnect a client after N+1 rejected records (100)\n"
          "  --send-timeout-ms MS     stall allowed to a non-lockstep client (2000)\n"
          "  --client-buffer BYTES    output the bus queues per client before waiting (8 MiB)\n"
          "  --gap-bits N             idle bits after each frame beyond its interframe space (0)\n"
          "  -q, --quiet              no progress messages\n",
          f);
}

static void on_signal(int sig)
{
    (void)sig;
    canbus_signalled = 1;
}

static int parse_i64(const char *s, int64_t lo, int64_t hi, int64_t *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 0);
    if (end == s || *end || errno || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

/* parse_i64 of the first n characters of s */
static int parse_i64_n(const char *s, size_t n, int64_t lo, int64_t hi, int64_t *out)
{
    char buf[32];
    if (n == 0 || n >= sizeof buf)
        return -1;
    memcpy(buf, s, n);
    buf[n] = 0;
    return parse_i64(buf, lo, hi, out);
}

/* --client NAME:ROLES:NODE, ROLES one or more of can, lockstep, own joined by '+'. */
static int parse_decl(const char *text, canbus_decl_t *d)
{
    memset(d, 0, sizeof *d);
    const char *c1 = strchr(text, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c1 || !c2 || c1 == text || (size_t)(c1 - text) >= CANBUS_NAME_LEN)
        return -1;
    memcpy(d->name, text, (size_t)(c1 - text));
    for (const char *p = c1 + 1;; p++) { /* each role; an empty one is an error */
        size_t n = strcspn(p, "+:");
        if (n == 3 && strncmp(p, "can", 3) == 0)
            d->roles |= CANBUS_ROLE_CAN;
        else if (n == 8 && strncmp(p, "lockstep", 8) == 0)
            d->roles |= CANBUS_ROLE_LOCKSTEP;
        else if (n == 3 && strncmp(p, "own", 3) == 0)
            d->roles |= CANBUS_ROLE_OWN;
        else
            return -1;
        p += n;
        if (*p != '+')
            break; /* at c2 */
    }
    int64_t node;
    if (parse_i64(c2 + 1, 0, UINT32_MAX, &node))
        return -1;
    d->node = (uint32_t)node;
    return 0;
}

static void free_opts(canbus_opts_t *o)
{
    free(o->faults);
    free(o->kills);
    free(o->order);
    free(o->decls);
}

int main(int argc, char **argv)
{
    enum {
        O_SOCKET = 256, O_BITRATE, O_QUANTUM, O_LOCKSTEP, O_DURATION, O_END, O_REALTIME,
        O_TRACE, O_STATS, O_MAXCL, O_FAULT, O_RECOVER, O_MAXREJ, O_SENDTO, O_CLBUF, O_GAP, O_KILL,
        O_HANG, O_ORDER, O_CONTROL, O_DECL, O_PACE,
        O_HELP
    };
    static const struct option longopts[] = {
        {"socket", required_argument, NULL, O_SOCKET},
        {"bitrate", required_argument, NULL, O_BITRATE},
        {"quantum-us", required_argument, NULL, O_QUANTUM},
        {"lockstep-clients", required_argument, NULL, O_LOCKSTEP},
        {"duration", required_argument, NULL, O_DURATION},
        {"end-ns", required_argument, NULL, O_END},
        {"realtime", no_argument, NULL, O_REALTIME},
        {"pace", required_argument, NULL, O_PACE},
        {"trace", required_argument, NULL, O_TRACE},
        {"stats", required_argument, NULL, O_STATS},
        {"max-clients", required_argument, NULL, O_MAXCL},
        {"fault", required_argument, NULL, O_FAULT},
        {"control-fd", required_argument, NULL, O_CONTROL},
        {"client", required_argument, NULL, O_DECL},
        {"kill-node", required_argument, NULL, O_KILL},
        {"hang-node", required_argument, NULL, O_HANG},
        {"client-order", required_argument, NULL, O_ORDER},
        {"bus-off-recovery", no_argument, NULL, O_RECOVER},
        {"max-rejects", required_argument, NULL, O_MAXREJ},
        {"send-timeout-ms", required_argument, NULL, O_SENDTO},
        {"client-buffer", required_argument, NULL, O_CLBUF},
        {"gap-bits", required_argument, NULL, O_GAP},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, O_HELP},
        {0},
    };
    canbus_opts_t o = {
        .bitrate = 1000000,
        .quantum_ns = 5000000,
        .end_ns = -1,
        .max_clients = 64,
        .max_rejects = 100,
        .send_timeout_ns = 2000000000,
        .client_buffer = 8u << 20,
        .control_fd = -1,
    };
    int opt, status = 0;
    int64_t v;
    char err[160];
    while ((opt = getopt_long(argc, argv, "q", longopts, NULL)) != -1) {
        const char *bad = NULL;
        switch (opt) {
        case O_SOCKET: o.socket_path = optarg; break;
        case O_BITRATE:
            if (parse_i64(optarg, 1000, 10000000, &v))
                bad = "--bitrate must be 1000..10000000";
            o.bitrate = (uint32_t)v;
            break;
        case O_QUANTUM:
            if (parse_i64(optarg, 1, 10000000, &v))
                bad = "--quantum-us must be 1..10000000";
            o.quantum_ns = v * 1000;
            break;
        case O_LOCKSTEP:
            if (parse_i64(optarg, 0, CANBUS_WIRE_MAX_CLIENTS, &v))
                bad = "--lockstep-clients must be 0..250";
            o.lockstep_clients = (int)v;
            break;
        case O_DURATION: {
            char *end;
            double d = strtod(optarg, &end);
            if (end == optarg || *end || !(d >= 0) || d > 9e9)
                bad = "--duration must be a number of seconds";
            else
                o.end_ns = (int64_t)llround(d * 1e9);
            break;
        }
        case O_END:
            if (parse_i64(optarg, 0, INT64_MAX, &o.end_ns))
                bad = "--end-ns must be >= 0";
            break;
        case O_REALTIME: o.realtime = true; break;
        case O_PACE: {
            char *end;
            double d = strtod(optarg, &end);
            if (end == optarg || *end || !(d > 0) || d > 1e6)
                bad = "--pace must be a factor > 0 (emulated seconds per wall second)";
            else
                o.pace = d;
            break;
        }
        case O_CONTROL:
            if (parse_i64(optarg, 3, 1 << 20, &v))
                bad = "--control-fd must be a descriptor number >= 3";
            o.control_fd = (int)v;
            break;
        case O_DECL: {
            canbus_decl_t *d = realloc(o.decls, (o.n_decls + 1) * sizeof *d);
            if (!d) {
                bad = "out of memory";
                break;
            }
            o.decls = d;
            if (parse_decl(optarg, &o.decls[o.n_decls]))
                bad = "--client must be NAME:ROLES:NODE, e.g. node1/io:can:1 or world:can+lockstep:0";
            else
                o.n_decls++;
            break;
        }
        case O_TRACE: o.trace_path = optarg; break;
        case O_STATS: o.stats_path = optarg; break;
        case O_MAXCL:
            if (parse_i64(optarg, 1, CANBUS_WIRE_MAX_CLIENTS, &v))
                bad = "--max-clients must be 1..250";
            o.max_clients = (int)v;
            break;
        case O_FAULT: {
            canbus_cli_fault_t *f = realloc(o.faults, (o.n_faults + 1) * sizeof *f);
            if (!f) {
                bad = "out of memory";
                break;
            }
            o.faults = f;
            f = &o.faults[o.n_faults];
            memset(f, 0, sizeof *f);
            if (canbus_fault_parse(optarg, &f->fault, f->target_name, sizeof f->target_name,
                                   err, sizeof err)) {
                bad = err;
                break;
            }
            /* An older form names no fault id: it gets cli1, cli2, ... by its place. */
            if (!f->fault.fid[0])
                snprintf(f->fault.fid, sizeof f->fault.fid, "cli%zu", o.n_faults + 1);
            for (size_t k = 0; k < o.n_faults; k++)
                if (strcmp(o.faults[k].fault.fid, f->fault.fid) == 0) {
                    snprintf(err, sizeof err, "--fault: fid %s given twice", f->fault.fid);
                    bad = err;
                }
            if (!bad)
                o.n_faults++;
            break;
        }
        case O_KILL:
        case O_HANG: {
            char *at = strchr(optarg, '@'), *end;
            double when = at ? strtod(at + 1, &end) : -1;
            if (!at || at == optarg || parse_i64_n(optarg, (size_t)(at - optarg), 1, 255, &v) ||
                end == at + 1 || *end || !(when >= 0) || when > 9e9) {
                bad = opt == O_KILL ? "--kill-node must be NODE@SECONDS, e.g. 2@120"
                                  : "--hang-node must be NODE@SECONDS, e.g. 2@120";
                break;
            }
            canbus_kill_t *k = realloc(o.kills, (o.n_kills + 1) * sizeof *k);
            if (!k) {
                bad = "out of memory";
                break;
            }
            o.kills = k;
            o.kills[o.n_kills++] = (canbus_kill_t){.node = (uint32_t)v,
                                                   .t_ns = (int64_t)llround(when * 1e9),
                                                   .sig = opt == O_KILL ? SIGKILL : SIGSTOP};
            break;
        }
        case O_ORDER: {
            /* names point into argv; the separators become NULs */
            o.n_order = 0;
            free(o.order);
            o.order = calloc(CANBUS_WIRE_MAX_CLIENTS, sizeof *o.order);
            if (!o.order) {
                bad = "out of memory";
                break;
            }
            for (char *save = NULL, *tok = strtok_r(optarg, ",", &save); tok;
                 tok = strtok_r(NULL, ",", &save)) {
                if (o.n_order >= 64 || strlen(tok) > CANBUS_NAME_LEN) {
                    bad = "--client-order: at most 64 names of at most 32 characters";
                    break;
                }
                o.order[o.n_order++] = tok;
            }
            break;
        }
        case O_RECOVER: o.recover = true; break;
        case O_MAXREJ:
            if (parse_i64(optarg, 0, 1000000000, &v))
                bad = "--max-rejects must be >= 0";
            o.max_rejects = (int)v;
            break;
        case O_SENDTO:
            if (parse_i64(optarg, 1, 3600000, &v))
                bad = "--send-timeout-ms must be 1..3600000";
            o.send_timeout_ns = v * 1000000;
            break;
        case O_CLBUF:
            if (parse_i64(optarg, 0, (int64_t)1 << 40, &v))
                bad = "--client-buffer must be >= 0";
            o.client_buffer = (size_t)v;
            break;
        case O_GAP:
            if (parse_i64(optarg, 0, 1000, &v))
                bad = "--gap-bits must be 0..1000";
            o.gap_bits = (uint32_t)v;
            break;
        case 'q': o.quiet = true; break;
        case O_HELP: usage(stdout); return 0;
        default: usage(stderr); return EXIT_USAGE;
        }
        if (bad) {
            fprintf(stderr, "ima-canbus: %s\n", bad);
            free_opts(&o);
            return EXIT_USAGE;
        }
    }
    if (o.realtime && o.pace > 0) {
        fprintf(stderr, "ima-canbus: --realtime and --pace exclude each other\n");
        free_opts(&o);
        return EXIT_USAGE;
    }
    if (!o.socket_path || optind != argc) {
        usage(stderr);
        free_opts(&o);
        return EXIT_USAGE;
    }

    /* Signals are blocked except inside ppoll(), so none is lost between checks. */
    struct sigaction sa = {.sa_handler = on_signal};
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    sigset_t block;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigprocmask(SIG_BLOCK, &block, NULL);

    canbus_bus_t *b = calloc(1, sizeof *b);
    if (!b) {
        free_opts(&o);
        return 1;
    }
    int rc = canbus_bus_open(b, &o);
    if (rc) {
        fprintf(stderr, "ima-canbus: cannot open the bus on %s: %s\n", o.socket_path,
                strerror(-rc));
        free(b);
        free_opts(&o);
        return 1;
    }
    rc = canbus_bus_run(b);
    if (rc) {
        fprintf(stderr, "ima-canbus: %s\n", strerror(-rc));
        status = 1;
    }
    if (o.stats_path && (rc = canbus_bus_write_stats(b, o.stats_path))) {
        fprintf(stderr, "ima-canbus: cannot write %s: %s\n", o.stats_path, strerror(-rc));
        status = 1;
    }
    canbus_bus_close(b);
    if (b->trace_error) {
        fprintf(stderr, "ima-canbus: writing the trace failed\n");
        status = 1;
    }
    free(b);
    free_opts(&o);
    return status;
}
