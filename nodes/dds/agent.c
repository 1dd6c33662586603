/* SPDX-License-Identifier: Apache-2.0 */
/* ima-dds-node: a node's DDS participant, serving its io partition's cross-channel link. */
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include "agent__agent.h"

static void usage(FILE *f)
{
    fputs("usage: ima-dds-node --node K --nodes N --socket PATH --domain D [--config FILE]\n"
          "                    [--realtime] [--xch-timeout-us 2000] [--lease-ms 1000]\n"
          "                    [--deadline-ms 150] [--startup-timeout-ms 20000]\n"
          "                    [--bind-device lo] [--trace FILE] [--stats FILE]\n"
          "                    [--security DIR] [--fault SPEC]... [--ske-pid-fd FD] [-q]\n"
          "  --config FILE  Cyclone DDS configuration (default: $IMA_DDS_CONFIG; the shipped\n"
          "                 one is config/dds/cyclonedds-loopback.xml)\n"
          "  --bind-device  interface every DDS socket is bound to (\"\" leaves them as\n"
          "                 Cyclone made them)\n"
          "  --security DIR the run's DDS Security files (ima launch makes them): identity\n"
          "                 and permissions CAs, nodeK.pem/.key, governance.p7s,\n"
          "                 permissions.p7s; without it the agent runs without security\n"
          "  --fault SPEC   dds_drop:fid=ID,at=TIME[,until=TIME][,period=TIME,on=TIME] or\n"
          "                 dds_delay:...,frames=N: this node's inputs and health are not\n"
          "                 published, or published N major frames late (faultinject/README.md)\n"
          "  --ske-pid-fd FD  an inherited pipe where the launcher writes the node's SKE pid:\n"
          "                 only a partition process of that SKE may then be io\n",
          f);
}

static bool parse_i64(const char *s, int64_t lo, int64_t hi, int64_t *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

enum {
    OPT_NODE = 256, OPT_NODES, OPT_SOCKET, OPT_DOMAIN, OPT_CONFIG, OPT_REALTIME, OPT_XCH_TIMEOUT,
    OPT_LEASE, OPT_DEADLINE, OPT_STARTUP, OPT_BIND, OPT_TRACE, OPT_STATS, OPT_FAULT, OPT_SECURITY,
    OPT_SKE,
    OPT_HELP,
};

static int parse_args(int argc, char **argv, agent_opts_t *o, dds_faults_t *faults)
{
    static const struct option longopts[] = {
        {"node", required_argument, NULL, OPT_NODE},
        {"nodes", required_argument, NULL, OPT_NODES},
        {"socket", required_argument, NULL, OPT_SOCKET},
        {"domain", required_argument, NULL, OPT_DOMAIN},
        {"config", required_argument, NULL, OPT_CONFIG},
        {"realtime", no_argument, NULL, OPT_REALTIME},
        {"xch-timeout-us", required_argument, NULL, OPT_XCH_TIMEOUT},
        {"lease-ms", required_argument, NULL, OPT_LEASE},
        {"deadline-ms", required_argument, NULL, OPT_DEADLINE},
        {"startup-timeout-ms", required_argument, NULL, OPT_STARTUP},
        {"bind-device", required_argument, NULL, OPT_BIND},
        {"trace", required_argument, NULL, OPT_TRACE},
        {"stats", required_argument, NULL, OPT_STATS},
        {"fault", required_argument, NULL, OPT_FAULT},
        {"security", required_argument, NULL, OPT_SECURITY},
        {"ske-pid-fd", required_argument, NULL, OPT_SKE},
        {"help", no_argument, NULL, OPT_HELP},
        {NULL, 0, NULL, 0},
    };
    int64_t node = 0, nodes = 0, domain = -1, v;
    *o = (agent_opts_t){.xch_timeout_ns = 2000 * 1000LL,
                        .lease_ns = 1000 * 1000000LL,
                        .deadline_ns = 150 * 1000000LL,
                        .startup_timeout_ns = 20000 * 1000000LL,
                        .bind_device = "lo",
                        .ske_pid_fd = -1};
    int c;
    char why[200];
    opterr = 0;
    while ((c = getopt_long(argc, argv, "q", longopts, NULL)) != -1) {
        const char *bad = NULL;
        switch (c) {
        case OPT_NODE:
            if (!parse_i64(optarg, 1, XCH_MAX_NODES, &node))
                bad = "--node wants 1..3";
            break;
        case OPT_NODES:
            if (!parse_i64(optarg, 1, XCH_MAX_NODES, &nodes))
                bad = "--nodes wants 1..3";
            break;
        case OPT_SOCKET:
            o->socket_path = optarg;
            break;
        case OPT_DOMAIN:
            /* DDSI maps domain d to UDP ports 7400 + 250 d + ...: above 232 they overflow */
            if (!parse_i64(optarg, 0, 232, &domain))
                bad = "--domain wants 0..232";
            break;
        case OPT_CONFIG:
            o->config = optarg;
            break;
        case OPT_REALTIME:
            o->realtime = true;
            break;
        case OPT_XCH_TIMEOUT:
            if (!parse_i64(optarg, 1, 60000000, &v))
                bad = "--xch-timeout-us wants 1..60000000";
            o->xch_timeout_ns = v * 1000;
            break;
        case OPT_LEASE:
            if (!parse_i64(optarg, 10, 3600000, &v))
                bad = "--lease-ms wants 10..3600000";
            o->lease_ns = v * 1000000;
            break;
        case OPT_DEADLINE:
            if (!parse_i64(optarg, 1, 3600000, &v))
                bad = "--deadline-ms wants 1..3600000";
            o->deadline_ns = v * 1000000;
            break;
        case OPT_STARTUP:
            if (!parse_i64(optarg, 0, 3600000, &v))
                bad = "--startup-timeout-ms wants 0..3600000";
            o->startup_timeout_ns = v * 1000000;
            break;
        case OPT_BIND:
            o->bind_device = optarg;
            break;
        case OPT_TRACE:
            o->trace_path = optarg;
            break;
        case OPT_STATS:
            o->stats_path = optarg;
            break;
        case OPT_SECURITY:
            if (!*optarg || strlen(optarg) > PATH_MAX - 32)
                bad = "--security wants a directory";
            o->security_dir = optarg;
            break;
        case OPT_FAULT:
            if (dds_fault_add(faults, optarg, why, sizeof why) != 0)
                bad = why;
            break;
        case OPT_SKE:
            if (!parse_i64(optarg, 3, 1 << 20, &v) || fcntl((int)v, F_GETFD) < 0)
                bad = "--ske-pid-fd wants an open descriptor >= 3";
            else {
                o->ske_pid_fd = (int)v;
                fcntl(o->ske_pid_fd, F_SETFD, FD_CLOEXEC);
                fcntl(o->ske_pid_fd, F_SETFL, O_NONBLOCK);
            }
            break;
        case 'q':
            o->quiet = true;
            break;
        case OPT_HELP:
            usage(stdout);
            exit(0);
        default:
            fprintf(stderr, "ima-dds-node: unknown option or missing value: %s\n",
                    argv[optind - 1]);
            usage(stderr);
            return -1;
        }
        if (bad) {
            fprintf(stderr, "ima-dds-node: %s (got %s)\n", bad, optarg);
            return -1;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "ima-dds-node: unexpected argument %s\n", argv[optind]);
        return -1;
    }
    if (!node || !nodes || !o->socket_path || domain < 0) {
        fputs("ima-dds-node: --node, --nodes, --socket and --domain are required\n", stderr);
        usage(stderr);
        return -1;
    }
    if (node > nodes) {
        fprintf(stderr, "ima-dds-node: --node %" PRId64 " is not one of --nodes %" PRId64 "\n",
                node, nodes);
        return -1;
    }
    if (strlen(o->bind_device) >= 16) {
        fprintf(stderr, "ima-dds-node: --bind-device name too long: %s\n", o->bind_device);
        return -1;
    }
    o->node = (unsigned)node;
    o->nodes = (unsigned)nodes;
    o->domain = (uint32_t)domain;
    if (!o->config)
        o->config = getenv("IMA_DDS_CONFIG");
    if (!o->config || !*o->config) {
        fputs("ima-dds-node: no Cyclone DDS configuration: pass --config FILE or set "
              "IMA_DDS_CONFIG (the shipped one is config/dds/cyclonedds-loopback.xml); "
              "Cyclone's default would send multicast on every interface\n",
              stderr);
        return -1;
    }
    return 0;
}

/* Points Cyclone at the configuration file, whatever CYCLONEDDS_URI said before. */
static int use_config(agent_t *a)
{
    const char *path = a->o.config;
    if (strncmp(path, "file://", 7) == 0)
        path += 7;
    static char real[PATH_MAX];
    if (!realpath(path, real) || access(real, R_OK) != 0) {
        fprintf(stderr, "ima-dds-node %s: cannot read the DDS configuration %s: %s\n",
                a->node_name, path, strerror(errno));
        return -1;
    }
    static char uri[PATH_MAX + 8];
    snprintf(uri, sizeof uri, "file://%s", real);
    a->o.config = real;
    return setenv("CYCLONEDDS_URI", uri, 1);
}

static int setup_signals(agent_t *a)
{
    struct sigaction sa = {.sa_handler = SIG_IGN};
    sigaction(SIGPIPE, &sa, NULL);
    /* Blocked before Cyclone starts its threads (they inherit the mask): SIGINT and SIGTERM
     * reach the main thread's signalfd only. */
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    if (sigprocmask(SIG_BLOCK, &set, NULL) != 0)
        return -1;
    a->sig_fd = signalfd(-1, &set, SFD_CLOEXEC | SFD_NONBLOCK);
    return a->sig_fd < 0 ? -1 : 0;
}

static void drain_wake(agent_t *a)
{
    char buf[64];
    while (read(a->wake_rd, buf, sizeof buf) > 0)
        ;
    atomic_store(&a->wake_pending, false);
}

static void check_signal(agent_t *a)
{
    struct signalfd_siginfo si;
    while (read(a->sig_fd, &si, sizeof si) == (ssize_t)sizeof si) {
        a->stop = true;
        if (agent_trace_begin(a, "dds_stop")) {
            fprintf(a->trace, ",\"signal\":%u", si.ssi_signo);
            agent_trace_end(a);
        }
    }
}

static struct timespec ts_of(int64_t ns)
{
    if (ns < 0)
        ns = 0;
    return (struct timespec){.tv_sec = ns / 1000000000, .tv_nsec = ns % 1000000000};
}

/* Waits for the other nodes' agents (or the startup timeout). */
static void discover(agent_t *a)
{
    int64_t start = agent_mono_ns(), end = start + a->o.startup_timeout_ns;
    uint32_t missing = 0;
    while (!a->stop) {
        agent_dds_process_events(a);
        agent_dds_take_all(a);
        if (agent_dds_discovery_complete(a, &missing))
            break;
        int64_t left = end - agent_mono_ns();
        if (left <= 0)
            break;
        struct pollfd p[2] = {{.fd = a->wake_rd, .events = POLLIN},
                              {.fd = a->sig_fd, .events = POLLIN}};
        struct timespec ts = ts_of(left);
        pthread_mutex_unlock(&a->state);
        int n = ppoll(p, 2, &ts, NULL);
        pthread_mutex_lock(&a->state);
        if (n > 0) {
            if (p[0].revents)
                drain_wake(a);
            if (p[1].revents)
                check_signal(a);
        }
    }
    /* Cyclone may have opened sockets since (it does not in this configuration; cheap). */
    a->bound_sockets = agent_dds_bind_sockets(a);
    uint32_t found = 0;
    for (unsigned k = 1; k <= a->o.nodes; k++)
        if (k != a->o.node && !(missing & (1u << (k - 1))))
            found |= 1u << (k - 1);
    if (agent_trace_begin(a, "dds_ready")) {
        fprintf(a->trace, ",\"domain\":%u,\"wait_ms\":%.1f,\"bound_sockets\":%u", a->o.domain,
                (agent_mono_ns() - start) / 1e6, a->bound_sockets);
        agent_trace_nodes(a, "discovered", found);
        agent_trace_nodes(a, "missing", missing);
        agent_trace_end(a);
    }
    /* Not there in time: dead for the run, so that nobody waits for them. */
    for (unsigned k = 1; k <= a->o.nodes; k++)
        if (missing & (1u << (k - 1))) {
            agent_log(a, "node%u's agent not found on DDS within the startup timeout", k);
            if (!a->peer[k - 1].dead) {
                a->peer[k - 1].dead = true;
                a->peer[k - 1].lost_wall_ns = agent_wall_ns();
                agree_set_dead(&a->agree, k);
                if (agent_trace_begin(a, "dds_peer_lost")) {
                    fprintf(a->trace, ",\"peer\":\"node%u\",\"reason\":\"not_discovered\","
                                      "\"was_alive\":false",
                            k);
                    agent_trace_end(a);
                }
            }
        }
}

#define HUNG_CHECK_NS (100 * 1000000LL)

static void run(agent_t *a)
{
    while (!a->stop) {
        /* Connections are taken once the SKE is known (--ske-pid-fd), and while nobody waits
         * to follow io; a negative descriptor is not polled. */
        bool ske_known = a->o.ske_pid_fd < 0;
        struct pollfd p[5] = {
            {.fd = a->sig_fd, .events = POLLIN},
            {.fd = a->wake_rd, .events = POLLIN},
            {.fd = a->io_fd, .events = POLLIN},
            {.fd = ske_known && a->io_next_fd < 0 ? a->listen_fd : -1, .events = POLLIN},
            {.fd = a->o.ske_pid_fd, .events = POLLIN}};
        struct timespec ts, *tsp = NULL;
        if (a->pending && a->o.realtime) {
            ts = ts_of(a->pend_start_ns + a->o.xch_timeout_ns - agent_mono_ns());
            tsp = &ts;
        } else if (a->pending && a->pend_waited) {
            ts = ts_of(HUNG_CHECK_NS); /* is the peer we wait for hung? */
            tsp = &ts;
        }
        pthread_mutex_unlock(&a->state);
        int n = ppoll(p, 5, tsp, NULL);
        pthread_mutex_lock(&a->state);
        if (n < 0 && errno != EINTR)
            break;
        if (n <= 0) {
            /* the real-time wait may be over; a peer may be hung; and, should a listener
             * call have been missed, what came in meanwhile is taken here */
            agent_io_catch_up(a);
            continue;
        }
        if (p[0].revents)
            check_signal(a);
        if (p[1].revents) {
            drain_wake(a);
            agent_io_catch_up(a);
        }
        if (p[2].revents && a->io_fd >= 0)
            agent_io_readable(a);
        if (p[3].revents)
            agent_io_accept(a);
        if (p[4].revents)
            agent_guard_read_ske(a);
    }
}

/* A launcher may start us with stdin or stdout closed: keep descriptors 0..2 taken, so that
 * no socket or trace file becomes "stdout" and receives the ready line. */
static void hold_std_fds(void)
{
    for (int fd = 0; fd <= 2; fd++)
        if (fcntl(fd, F_GETFD) == -1 && errno == EBADF) {
            int n = open("/dev/null", O_RDWR);
            if (n >= 0 && n != fd)
                close(n); /* not the lowest free descriptor after all */
        }
}

int main(int argc, char **argv)
{
    static agent_t agent;
    hold_std_fds();
    agent_t *a = &agent;
    a->listen_fd = a->io_fd = a->io_next_fd = a->sig_fd = a->wake_rd = a->wake_wr = -1;
    if (parse_args(argc, argv, &a->o, &a->faults) != 0)
        return 2;
    snprintf(a->node_name, sizeof a->node_name, "node%u", a->o.node);
    a->start_mono_ns = agent_mono_ns();
    agree_init(&a->agree, a->o.node, a->o.nodes);
    pthread_mutex_init(&a->lock, NULL);
    pthread_mutex_init(&a->state, NULL);
    /* Held by this thread from here on, but while it waits (agent__agent.h). */
    pthread_mutex_lock(&a->state);
    a->answer_in_listener = true;
    atomic_init(&a->wake_pending, false);

    int status = 1;
    int wake[2];
    if (use_config(a) != 0 || setup_signals(a) != 0)
        goto out;
    if (pipe2(wake, O_NONBLOCK | O_CLOEXEC) != 0)
        goto out;
    a->wake_rd = wake[0];
    a->wake_wr = wake[1];
    if (agent_lat_init(&a->xch_lat) != 0 || agent_lat_init(&a->dds_lat) != 0) {
        fprintf(stderr, "ima-dds-node %s: out of memory\n", a->node_name);
        goto out;
    }
    if (a->o.trace_path) {
        a->trace = fopen(a->o.trace_path, "w");
        if (!a->trace) {
            fprintf(stderr, "ima-dds-node %s: cannot write the trace %s: %s\n", a->node_name,
                    a->o.trace_path, strerror(errno));
            goto out;
        }
    }
    /* Listening before DDS starts: an io partition that connects early waits in the backlog
     * for its WELCOME instead of failing. */
    if (agent_io_listen(a) != 0)
        goto out;
    if (agent_dds_start(a) != 0)
        goto out_dds;
    discover(a);
    if (!a->stop) {
        /* The launcher waits for this line. A closed stdout is fine (SIGPIPE is ignored). */
        a->ready = true;
        fputs("ready\n", stdout);
        fflush(stdout);
        run(a);
    }
    status = 0;
out_dds:
    agent_io_shutdown(a);
    /* Deleting the participant waits for running listeners: they must not wait for us. */
    a->answer_in_listener = false;
    agent_dds_census(a);
    pthread_mutex_unlock(&a->state);
    agent_dds_stop(a);
    pthread_mutex_lock(&a->state);
    if (agent_write_stats(a) != 0)
        status = 1;
out:
    agent_io_shutdown(a);
    if (a->trace) {
        agent_trace_simple(a, "dds_exit");
        fclose(a->trace);
    }
    agent_lat_free(&a->xch_lat);
    agent_lat_free(&a->dds_lat);
    return status;
}
