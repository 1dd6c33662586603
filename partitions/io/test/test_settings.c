/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of io's settings: the arguments `ima deploy` writes, and every way they can be
 * wrong. */
#include <string.h>

#include "io_core.h"
#include "rpas/unit_check.h"

#define GOOD "--node=node2", "--node-index=2", "--nodes=1,2,3", "--canbus=can.sock", \
             "--dds=dds2.sock", "--vote-thresholds=0.1,0.2,0.3,0.05", "--vote-persist=3", \
             "--membership-missed-frames=2"

static int parse(io_settings_t *s, char *err, int argc, char **argv)
{
    return io_settings_parse(s, argc, argv, err, 200);
}

static void test_good(void)
{
    char *argv[] = {"io", GOOD};
    io_settings_t s;
    char err[200] = "";
    CHECK(parse(&s, err, 9, argv) == 0);
    CHECK(!strcmp(s.node, "node2"));
    CHECK(s.channel == 1);
    CHECK(s.node_mask == 7 && s.n_nodes == 3);
    CHECK(!strcmp(s.canbus, "can.sock") && !strcmp(s.dds, "dds2.sock"));
    CHECK_NEAR(s.vote_threshold[1], 0.2, 0);
    CHECK_NEAR(s.vote_threshold[3], 0.05, 0);
    CHECK(s.vote_persist == 3 && s.membership_misses == 2);
    CHECK(s.n_faults == 0);
}

static void test_sparse_nodes(void)
{
    /* nodes 1 and 3: channels span 0..2, node 2 is not a member */
    char *argv[] = {"io", "--node=n3", "--node-index=3", "--nodes=1,3", "--canbus=c", "--dds=d",
                    "--vote-thresholds=0,0,0,0", "--vote-persist=1", "--membership-missed-frames=1"};
    io_settings_t s;
    char err[200];
    CHECK(parse(&s, err, 9, argv) == 0);
    CHECK(s.node_mask == 5 && s.n_nodes == 3 && s.channel == 2);
}

static void test_faults(void)
{
    /* the older test switch is a permanent bias named test-cmd-bias */
    char *argv[] = {"io", GOOD, "--test-cmd-bias=rud=-0.25@12.5",
                    "--fault=wrong_output:fid=w2,at=30s,until=40s,mode=random,axis=thr,seed=9",
                    "--fault=wrong_output:fid=w3,at=1s,period=2s,on=1s,mode=oscillating,axis=ail,"
                    "value=0.2,period_osc=500ms"};
    io_settings_t s;
    char err[200] = "";
    CHECK(parse(&s, err, 12, argv) == 0);
    CHECK(s.n_faults == 3);
    const fi_wo_t *b = &s.fault[0];
    CHECK(!strcmp(b->spec.fid, "test-cmd-bias") && b->mode == FI_WO_BIAS && b->axis == 2);
    CHECK_NEAR(b->value, -0.25, 0);
    CHECK(b->spec.at_ns == 12500000000LL && b->spec.duration == FI_PERMANENT);
    CHECK(s.fault[1].mode == FI_WO_RANDOM && s.fault[1].axis == 3 && s.fault[1].seed == 9);
    CHECK(s.fault[1].lo == 0 && s.fault[1].hi == 1 && s.fault[1].spec.duration == FI_TRANSIENT);
    CHECK(s.fault[2].spec.duration == FI_INTERMITTENT && s.fault[2].period_osc_ns == 500000000);
    CHECK(!strcmp(io_axis_name(2), "rud"));
}

/* Each bad word in place of one good one (or added) is refused with a message naming it. */
static void test_refused(void)
{
    static const struct {
        const char *word, *says;
    } bad[] = {
        {"--node-index=4", "--node-index=4"},
        {"--node-index=0", "--node-index=0"},
        {"--nodes=1,1,2", "--nodes"},
        {"--nodes=1,4", "--nodes"},
        {"--nodes=", "--nodes"},
        {"--vote-thresholds=0.1,0.1,0.1", "--vote-thresholds"},
        {"--vote-thresholds=0.1,0.1,0.1,-1", "--vote-thresholds"},
        {"--vote-thresholds=0.1,0.1,0.1,nan", "--vote-thresholds"},
        {"--vote-thresholds=0.1,0.1,0.1,0.1,", "--vote-thresholds"},
        {"--vote-persist=0", "--vote-persist"},
        {"--membership-missed-frames=x", "--membership-missed-frames"},
        {"--node=", "--node="},
        {"--colour=red", "unknown argument '--colour'"},
        {"plain", "'plain' is not --NAME=VALUE"},
        {"--test-cmd-bias=yaw=1@2", "--test-cmd-bias"},
        {"--test-cmd-bias=elev=1@-2", "--test-cmd-bias"},
        {"--fault=wrong_output:fid=a,at=1s,mode=bias,axis=yaw,value=1", "axis=yaw"},
        {"--fault=wrong_output:fid=a,at=1s,mode=bias,axis=elev", "needs value"},
        {"--fault=crash:fid=a,at=1s", "not a wrong_output fault"},
        {"--fault=wrong_output:at=1s,mode=hardover,axis=elev", "fid=ID is required"},
        {"--node=again", "given twice"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char *argv[] = {"io", GOOD, (char *)bad[i].word};
        io_settings_t s;
        char err[200] = "";
        int rc = parse(&s, err, 10, argv);
        CHECK(rc == -1);
        if (!strstr(err, bad[i].says)) {
            fprintf(stderr, "for %s: message '%s' does not say '%s'\n", bad[i].word, err, bad[i].says);
            unit_failures++;
        }
    }
    /* the node must be one of the system's nodes */
    char *argv[] = {"io", "--node=n2", "--node-index=2", "--nodes=1,3", "--canbus=c", "--dds=d",
                    "--vote-thresholds=0,0,0,0", "--vote-persist=1", "--membership-missed-frames=1"};
    io_settings_t s;
    char err[200];
    CHECK(parse(&s, err, 9, argv) == -1 && strstr(err, "not one of --nodes"));
}

static void test_missing(void)
{
    char *good[] = {GOOD};
    for (int drop = 0; drop < 8; drop++) {
        char *argv[9] = {"io"};
        int n = 1;
        for (int i = 0; i < 8; i++)
            if (i != drop)
                argv[n++] = good[i];
        io_settings_t s;
        char err[200] = "";
        CHECK(parse(&s, err, n, argv) == -1);
        char want[64];
        snprintf(want, sizeof want, "%.*s is missing", (int)(strchr(good[drop], '=') - good[drop]), good[drop]);
        if (!strstr(err, want)) {
            fprintf(stderr, "dropping %s: '%s'\n", good[drop], err);
            unit_failures++;
        }
    }
}

int main(void)
{
    RUN(test_good);
    RUN(test_sparse_nodes);
    RUN(test_faults);
    RUN(test_refused);
    RUN(test_missing);
    return UNIT_RESULT();
}
