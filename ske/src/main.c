/* SPDX-License-Identifier: Apache-2.0 */
/* ima-ske: one emulated ARINC 653 processor, run from the command line. */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ske/config.h"
#include "ske/ske.h"

static ske_t *g_ske; /* the program's one SKE, for its signal handlers */

static void on_stop(int sig)
{
    if (g_ske)
        ske_request_stop(g_ske, sig);
}

static void on_child(int sig)
{
    (void)sig;
    if (g_ske)
        ske_notify_child(g_ske);
}

static void usage(FILE *f)
{
    fputs("usage: ima-ske [options] MODULE.xml\n"
          "  --frames N            run N major frames, then stop (default: until SIGINT/SIGTERM)\n"
          "  --realtime            start windows on CLOCK_MONOTONIC (default: emulated time)\n"
          "  --emulated            force emulated time whatever the module says\n"
          "  --trace FILE          write the JSON-lines trace to FILE ('-' for stdout)\n"
          "  --stats FILE          write a JSON summary to FILE at the end\n"
          "  --node NAME           node name in the trace (default: the module's, or node1)\n"
          "  --schema DIR          folder holding ima653_module.xsd\n"
          "  --partition-path DIRS colon-separated folders searched for partition programs\n"
          "                        (default: $IMA_PARTITION_PATH)\n"
          "  --check               validate the module and exit\n"
          "  --lockstep SOCKET     advance time in the quanta of the CAN bus at SOCKET (a flight);\n"
          "                        runs until the bus ends the run\n"
          "  --node-index N        this node's number on the bus (redundancy channel), 0..3\n"
          "  --fault SPEC          inject a fault (repeatable): CLASS:fid=ID,at=TIME[,until=TIME]\n"
          "                        [,period=TIME,on=TIME],partition=NAME[,process=NAME][,port=NAME]\n"
          "                        [,value=X], or module_reset:fid=ID,at=TIME (docs/trace-format.md)\n"
          "  --trace-port-hashes   trace a port_hash event per source port written in a window\n"
          "  --output-dir DIR      folder of the partitions' relative output files (ima:Linux\n"
          "                        OutputFile; default: the module file's folder)\n"
          "  --test-switch NAME[=VALUE]  test only: break an isolation guarantee on purpose\n"
          "                        (overrun-eats-next-window, hm-action=PARTITION:ACTION,\n"
          "                        corrupt-port=PARTITION.PORT@TIME)\n"
          "  -q, --quiet           print nothing but errors\n"
          "exit status: 0 done, 1 run-time failure, 2 usage, invalid module or fault,\n"
          "             3 shut down by the health monitor (module-level SHUTDOWN), 128+N stopped by signal N\n",
          f);
}

static int parse_frames(const char *s, int64_t *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno || *end || v < 0)
        return -1;
    *out = v;
    return 0;
}

int main(int argc, char **argv)
{
    enum { O_FRAMES = 1000, O_REALTIME, O_EMULATED, O_TRACE, O_STATS, O_NODE, O_SCHEMA, O_PPATH, O_CHECK, O_LOCKSTEP, O_NODE_INDEX,
           O_FAULT, O_PORT_HASHES, O_TEST_SWITCH, O_OUTPUT_DIR };
    static const struct option longopts[] = {
        {"frames", required_argument, NULL, O_FRAMES},
        {"realtime", no_argument, NULL, O_REALTIME},
        {"emulated", no_argument, NULL, O_EMULATED},
        {"trace", required_argument, NULL, O_TRACE},
        {"stats", required_argument, NULL, O_STATS},
        {"node", required_argument, NULL, O_NODE},
        {"schema", required_argument, NULL, O_SCHEMA},
        {"partition-path", required_argument, NULL, O_PPATH},
        {"check", no_argument, NULL, O_CHECK},
        {"lockstep", required_argument, NULL, O_LOCKSTEP},
        {"node-index", required_argument, NULL, O_NODE_INDEX},
        {"fault", required_argument, NULL, O_FAULT},
        {"trace-port-hashes", no_argument, NULL, O_PORT_HASHES},
        {"test-switch", required_argument, NULL, O_TEST_SWITCH},
        {"output-dir", required_argument, NULL, O_OUTPUT_DIR},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    ske_run_opts_t ro = {.frames = -1, .time_mode = -1};
    ske_load_opts_t lo = {.partition_path = getenv("IMA_PARTITION_PATH"), .resolve_executables = true};
    bool check = false;
    /* Each option's text stays in argv for the whole run. */
    const char **faults = calloc((size_t)argc, sizeof *faults);
    const char **switches = calloc((size_t)argc, sizeof *switches);
    if (!faults || !switches) {
        fprintf(stderr, "ima-ske: error: out of memory\n");
        return 1;
    }
    ro.faults = faults;
    ro.test_switches = switches;
    int c;
    while ((c = getopt_long(argc, argv, "qh", longopts, NULL)) != -1) {
        switch (c) {
        case O_FRAMES:
            if (parse_frames(optarg, &ro.frames) != 0) {
                fprintf(stderr, "ima-ske: error: --frames wants a non-negative integer, not '%s'\n", optarg);
                return 2;
            }
            break;
        case O_REALTIME: ro.time_mode = SKE_TIME_REALTIME; break;
        case O_EMULATED: ro.time_mode = SKE_TIME_EMULATED; break;
        case O_TRACE: ro.trace_path = optarg; break;
        case O_STATS: ro.stats_path = optarg; break;
        case O_NODE: ro.node = optarg; break;
        case O_LOCKSTEP: ro.lockstep_path = optarg; break;
        case O_NODE_INDEX: {
            int64_t v;
            if (parse_frames(optarg, &v) != 0 || v > 3) {
                fprintf(stderr, "ima-ske: error: --node-index wants 0..3, not '%s'\n", optarg);
                return 2;
            }
            ro.node_index = (uint32_t)v;
            break;
        }
        case O_FAULT: faults[ro.n_faults++] = optarg; break;
        case O_PORT_HASHES: ro.trace_port_hashes = true; break;
        case O_OUTPUT_DIR: ro.output_dir = optarg; break;
        case O_TEST_SWITCH: switches[ro.n_test_switches++] = optarg; break;
        case O_SCHEMA: lo.schema_dir = optarg; break;
        case O_PPATH: lo.partition_path = optarg; break;
        case O_CHECK: check = true; break;
        case 'q': ro.quiet = true; break;
        case 'h': usage(stdout); return 0;
        default: usage(stderr); return 2;
        }
    }
    if (optind != argc - 1) {
        usage(stderr);
        return 2;
    }
    const char *path = argv[optind];
    ske_module_cfg_t *cfg = NULL;
    ske_diag_t diag;
    char line[2048];
    int rc = ske_config_load(path, &lo, &cfg, &diag);
    if (rc != SKE_OK) {
        ske_diag_format(&diag, line, sizeof line);
        fprintf(stderr, "%s\n", line);
        return 2;
    }
    char err[1024] = "";
    if (ske_check_options(cfg, &ro, err, sizeof err) != SKE_OK) {
        fprintf(stderr, "ima-ske: error: %s\n", err);
        ske_config_free(cfg);
        return 2;
    }
    if (check) {
        if (!ro.quiet)
            printf("%s: valid module '%s': %d partitions, %d windows, %d channels, major frame %.6f s\n",
                   path, cfg->module_name, cfg->n_partitions, cfg->n_windows, cfg->n_channels,
                   (double)cfg->major_frame_ns / 1e9);
        ske_config_free(cfg);
        return 0;
    }

    ske_t *ske = NULL;
    if (ske_create(cfg, &ro, &ske, err, sizeof err) != SKE_OK) {
        fprintf(stderr, "ima-ske: error: %s\n", err);
        ske_config_free(cfg);
        return 1;
    }
    g_ske = ske;
    /* No SA_RESTART: a signal must interrupt the supervisor's futex waits. */
    struct sigaction sa = {.sa_handler = on_stop};
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
    struct sigaction sc = {.sa_handler = on_child, .sa_flags = SA_NOCLDSTOP};
    sigemptyset(&sc.sa_mask);
    sigaction(SIGCHLD, &sc, NULL);
    signal(SIGPIPE, SIG_IGN);

    rc = ske_run(ske, err, sizeof err);
    int sig = ske_stop_signal(ske);
    bool shutdown = ske_shut_down_by_hm(ske);
    g_ske = NULL;
    ske_destroy(ske);
    ske_config_free(cfg);
    if (rc != SKE_OK) {
        fprintf(stderr, "ima-ske: error: %s\n", err);
        return 1;
    }
    if (sig)
        return 128 + sig;
    return shutdown ? 3 : 0;
}
