/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the module loader: exact number parsing, every field loaded from the example
 * module, and one diagnostic (file, line, element, rule) per invalid module. */
#include <limits.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ske/config.h"
#include "ske__config.h"
#include "ske_test.h"

#ifndef IMA_SOURCE_DIR
#error "IMA_SOURCE_DIR must name the source tree"
#endif

#define SCHEMA_DIR IMA_SOURCE_DIR "/config/schema"
#define EXAMPLE IMA_SOURCE_DIR "/config/examples/three_partitions.xml"

static const ske_load_opts_t no_resolve = {.schema_dir = SCHEMA_DIR, .resolve_executables = false};

/* Folder for the modules and programs the tests write; removed at exit. */
static char tmp_dir[] = "/tmp/ske_test_config.XXXXXX";

/* ---- text helpers --------------------------------------------------------------------- */

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = '\0';
    fclose(f);
    return s;
}

static int line_at(const char *text, const char *pos)
{
    int line = 1;
    for (const char *p = text; p < pos; p++)
        line += *p == '\n';
    return line;
}

/* Line of the first occurrence of `needle`, or -1. */
static int line_of(const char *text, const char *needle)
{
    const char *p = strstr(text, needle);
    return p ? line_at(text, p) : -1;
}

/* Line of the '>' that ends the start tag containing the first occurrence of `needle`. */
static int tag_end_line(const char *text, const char *needle)
{
    const char *p = strstr(text, needle);
    const char *gt = p ? strchr(p, '>') : NULL;
    return gt ? line_at(text, gt) : -1;
}

/* `text` with its only occurrence of `from` replaced; NULL if `from` is absent or repeated
 * (a substitution that could hit two places would make a case ambiguous). */
static char *replace_once(const char *text, const char *from, const char *to)
{
    const char *p = strstr(text, from);
    if (!p || strstr(p + 1, from))
        return NULL;
    size_t head = (size_t)(p - text), nf = strlen(from), nt = strlen(to);
    char *out = malloc(strlen(text) - nf + nt + 1);
    if (!out)
        return NULL;
    memcpy(out, text, head);
    memcpy(out + head, to, nt);
    strcpy(out + head + nt, p + nf);
    return out;
}

static bool write_file(const char *path, const char *text, mode_t mode)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return false;
    bool ok = fputs(text, f) >= 0;
    ok = fclose(f) == 0 && ok;
    return ok && chmod(path, mode) == 0;
}

/* Writes `text` as tmp_dir/name and returns its path (static buffer). */
static const char *write_module(const char *name, const char *text)
{
    static char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/%s", tmp_dir, name);
    return write_file(path, text, 0644) ? path : NULL;
}

/* ---- numbers -------------------------------------------------------------------------- */

static void test_parse_seconds(void)
{
    static const struct {
        const char *s;
        int64_t ns;
    } good[] = {
        {"0.05", 50000000},
        {"0.000000001", 1},
        {"1", 1000000000},
        {"0", 0},
        {"0.0", 0},
        {"0.010", 10000000},
        {"0.000125", 125000},
        {"0.999999999", 999999999},
        {"00.5", 500000000},
        {"12.5", 12500000000},
        {"0.1", 100000000}, /* not 99999999: no binary floating point on the way */
        {"0.3", 300000000},
        {"9000000000", INT64_C(9000000000000000000)},
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        int64_t ns = -1;
        if (!ske_parse_seconds(good[i].s, &ns))
            fprintf(stderr, "  rejected \"%s\"\n", good[i].s);
        CHECK(ske_parse_seconds(good[i].s, &ns));
        CHECK_EQ(ns, good[i].ns);
    }
    static const char *const bad[] = {
        "0.1234567891", /* 10 decimals: below the nanosecond */
        "0.0000000001",
        "-1", "-0", "+1", "1e-3", "1E3", "", " 1", "1 ", "1.", ".5", "1.2.3", "0x10", "1,5",
        "abc", "0.05s", "inf", "nan",
        "9223372037",            /* > INT64_MAX ns */
        "9223372036.854775808",  /* INT64_MAX + 1 ns */
        "18446744073.709551616", /* 2^64 ns: would wrap to 0 in unsigned arithmetic */
        "99999999999999999999",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        int64_t ns = -1;
        if (ske_parse_seconds(bad[i], &ns))
            fprintf(stderr, "  accepted \"%s\" as %lld ns\n", bad[i], (long long)ns);
        CHECK(!ske_parse_seconds(bad[i], &ns));
    }
    int64_t ns;
    CHECK(!ske_parse_seconds(NULL, &ns));
}

static void test_parse_u64(void)
{
    static const struct {
        const char *s;
        uint64_t v;
    } good[] = {
        {"0", 0},
        {"42", 42},
        {"007", 7}, /* decimal, not octal */
        {"010", 10},
        {"0x4000000", 0x4000000},
        {"0X1f", 31},
        {"0xffffffffffffffff", UINT64_MAX},
        {"18446744073709551615", UINT64_MAX},
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        uint64_t v = 1;
        CHECK(ske_parse_u64(good[i].s, &v));
        CHECK_EQ_U(v, good[i].v);
    }
    static const char *const bad[] = {
        "", "12x", "x12", "0x", "0xg", "0x1g", "1 ", " 1", "-1", "+1", "1.0", "1e3", "0b101",
        "18446744073709551616", "0x10000000000000000", "99999999999999999999999",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint64_t v = 0;
        if (ske_parse_u64(bad[i], &v))
            fprintf(stderr, "  accepted \"%s\" as %llu\n", bad[i], (unsigned long long)v);
        CHECK(!ske_parse_u64(bad[i], &v));
    }
    uint64_t v;
    CHECK(!ske_parse_u64(NULL, &v));
}

/* ---- the example module --------------------------------------------------------------- */

/* The loader records an element's line; where a start tag spans several lines it must at
 * least be one of them (which one: see defect_line_of_multiline_start_tag). */
#define CHECK_TAG_LINE(actual, text, needle)                                                  \
    do {                                                                                      \
        int tl_ = (actual), ts_ = line_of((text), (needle)), te_ = tag_end_line((text), (needle)); \
        if (ts_ < 0 || tl_ < ts_ || tl_ > te_) {                                              \
            fprintf(stderr, "%s:%d: check failed: line of '%s': got %d, expected %d..%d\n",   \
                    __FILE__, __LINE__, (needle), tl_, ts_, te_);                             \
            ske_test_failures++;                                                              \
        }                                                                                     \
    } while (0)

static void check_port(const ske_port_cfg_t *p, const char *name, ske_port_kind_t kind,
                       ske_port_dir_t dir, uint32_t max_size, uint32_t max_nb, int64_t refresh,
                       int channel, const char *text)
{
    char needle[64];
    CHECK_STR(p->name, name);
    CHECK_EQ(p->kind, kind);
    CHECK_EQ(p->dir, dir);
    CHECK_EQ_U(p->max_size, max_size);
    CHECK_EQ_U(p->max_nb, max_nb);
    CHECK_EQ(p->refresh_ns, refresh);
    CHECK_EQ(p->channel, channel);
    snprintf(needle, sizeof needle, "Name=\"%s\"", name);
    CHECK_EQ(p->line, line_of(text, needle));
}

static void check_window(const ske_window_cfg_t *w, int32_t id, int partition, int64_t offset,
                         int64_t duration, bool period_start, const char *text)
{
    char needle[64];
    CHECK_EQ(w->id, id);
    CHECK_EQ(w->partition, partition);
    CHECK_EQ(w->offset_ns, offset);
    CHECK_EQ(w->duration_ns, duration);
    CHECK_EQ(w->period_start, period_start);
    snprintf(needle, sizeof needle, "<Window_Schedule WindowIdentifier=\"%d\"", id);
    CHECK_TAG_LINE(w->line, text, needle);
}

static void test_load_example(void)
{
    char *text = read_text(EXAMPLE);
    REQUIRE(text);
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    int rc = ske_config_load(EXAMPLE, &no_resolve, &m, &d);
    if (rc != SKE_OK) {
        char line[2048];
        ske_diag_format(&d, line, sizeof line);
        fprintf(stderr, "  %s\n", line);
        free(text);
    }
    CHECK_EQ(rc, SKE_OK);
    REQUIRE(m);

    CHECK_STR(m->path, EXAMPLE);
    CHECK_STR(m->module_name, "three_partitions");
    CHECK_STR(m->node, "node1");
    CHECK_EQ(m->time_mode, SKE_TIME_EMULATED);
    CHECK_EQ(m->major_frame_ns, 50000000);

    CHECK_EQ(m->n_partitions, 3);
    REQUIRE(m->n_partitions == 3);
    const ske_partition_cfg_t *prod = &m->partitions[0], *cons = &m->partitions[1],
                              *mon = &m->partitions[2];

    CHECK_EQ(prod->id, 1);
    CHECK_STR(prod->name, "producer");
    CHECK_STR(prod->criticality, "LEVEL_B");
    CHECK(!prod->system_partition);
    CHECK_STR(prod->entry_point, "main");
    CHECK_STR(prod->exe_name, "ex_producer");
    CHECK_STR(prod->executable, ""); /* not resolved */
    CHECK_EQ(prod->argc, 1);
    CHECK_STR(prod->argv[0], "producer");
    CHECK(prod->argv[1] == NULL);
    CHECK_EQ(prod->period_ns, 50000000);
    CHECK_EQ(prod->duration_ns, 15000000); /* two windows: 10 ms + 5 ms */
    CHECK_EQ(prod->period_anchor_ns, 0);
    CHECK_EQ(prod->n_windows, 2);
    CHECK_EQ_U(prod->memory_bytes, 0x4000000);
    CHECK_TAG_LINE(prod->line, text, "<Partition PartitionIdentifier=\"1\"");
    CHECK_EQ(prod->n_ports, 2);
    check_port(&prod->ports[0], "SP_STATE", SKE_PORT_SAMPLING, SKE_DIR_SOURCE, 64, 0, 100000000, 0,
               text);
    check_port(&prod->ports[1], "QP_CMD", SKE_PORT_QUEUING, SKE_DIR_SOURCE, 32, 8, 0, 1, text);
    CHECK_EQ(prod->n_processes, 1);
    CHECK_STR(prod->processes[0].name, "produce");
    CHECK_EQ_U(prod->processes[0].stack_size, 65536);
    CHECK_EQ(prod->processes[0].line, line_of(text, "<Process Name=\"produce\""));

    CHECK_EQ(cons->id, 2);
    CHECK_STR(cons->name, "consumer");
    CHECK_STR(cons->criticality, "LEVEL_B");
    CHECK(!cons->system_partition);
    CHECK_STR(cons->exe_name, "ex_consumer");
    CHECK_EQ(cons->argc, 1);
    CHECK_STR(cons->argv[0], "consumer");
    CHECK_EQ(cons->period_ns, 50000000);
    CHECK_EQ(cons->duration_ns, 12000000);
    CHECK_EQ(cons->period_anchor_ns, 10000000);
    CHECK_EQ(cons->n_windows, 1);
    CHECK_EQ_U(cons->memory_bytes, 0x4000000);
    CHECK_TAG_LINE(cons->line, text, "<Partition PartitionIdentifier=\"2\"");
    CHECK_EQ(cons->n_ports, 2);
    check_port(&cons->ports[0], "SP_STATE_IN", SKE_PORT_SAMPLING, SKE_DIR_DESTINATION, 64, 0,
               100000000, 0, text);
    check_port(&cons->ports[1], "QP_CMD_IN", SKE_PORT_QUEUING, SKE_DIR_DESTINATION, 32, 16, 0, 1,
               text);
    CHECK_EQ(cons->n_processes, 2);
    CHECK_STR(cons->processes[0].name, "sample");
    CHECK_STR(cons->processes[1].name, "receive");
    CHECK_EQ_U(cons->processes[1].stack_size, 65536);
    CHECK_EQ(cons->processes[1].line, line_of(text, "<Process Name=\"receive\""));

    CHECK_EQ(mon->id, 3);
    CHECK_STR(mon->name, "monitor");
    CHECK_STR(mon->criticality, "LEVEL_E");
    CHECK_STR(mon->exe_name, "ex_monitor");
    CHECK_EQ(mon->period_ns, 50000000);
    CHECK_EQ(mon->duration_ns, 8000000);
    CHECK_EQ(mon->period_anchor_ns, 38000000);
    CHECK_EQ(mon->n_windows, 1);
    CHECK_EQ_U(mon->memory_bytes, 0x2000000);
    CHECK_TAG_LINE(mon->line, text, "<Partition PartitionIdentifier=\"3\"");
    CHECK_EQ(mon->n_ports, 1);
    check_port(&mon->ports[0], "SP_STATE_MON", SKE_PORT_SAMPLING, SKE_DIR_DESTINATION, 64, 0,
               100000000, 0, text);
    CHECK_EQ(mon->n_processes, 1);
    CHECK_STR(mon->processes[0].name, "watch");

    /* Windows sorted by offset, whatever the order of the Partition_Schedule elements. */
    CHECK_EQ(m->n_windows, 4);
    REQUIRE(m->n_windows == 4);
    check_window(&m->windows[0], 1, 0, 0, 10000000, true, text);
    check_window(&m->windows[1], 2, 1, 10000000, 12000000, true, text);
    check_window(&m->windows[2], 4, 0, 30000000, 5000000, false, text);
    check_window(&m->windows[3], 5, 2, 38000000, 8000000, true, text);

    CHECK_EQ(m->n_channels, 2);
    REQUIRE(m->n_channels == 2);
    const ske_channel_cfg_t *st = &m->channels[0], *cmd = &m->channels[1];
    CHECK_EQ(st->id, 1);
    CHECK_STR(st->name, "state");
    CHECK_EQ(st->kind, SKE_PORT_SAMPLING);
    CHECK(st->src.partition == 0 && st->src.port == 0);
    CHECK_EQ(st->n_dst, 2);
    CHECK(st->dst[0].partition == 1 && st->dst[0].port == 0);
    CHECK(st->dst[1].partition == 2 && st->dst[1].port == 0);
    CHECK_EQ(st->line, line_of(text, "<Channel ChannelIdentifier=\"1\""));
    CHECK_EQ(cmd->id, 2);
    CHECK_STR(cmd->name, "commands");
    CHECK_EQ(cmd->kind, SKE_PORT_QUEUING);
    CHECK(cmd->src.partition == 0 && cmd->src.port == 1);
    CHECK_EQ(cmd->n_dst, 1);
    CHECK(cmd->dst[0].partition == 1 && cmd->dst[0].port == 1);
    CHECK_EQ(cmd->line, line_of(text, "<Channel ChannelIdentifier=\"2\""));

    CHECK_EQ(ske_config_partition_by_id(m, 3), 2);
    CHECK_EQ(ske_config_partition_by_id(m, 4), -1);
    CHECK_EQ(ske_config_port_by_name(cons, "QP_CMD_IN"), 1);
    CHECK_EQ(ske_config_port_by_name(cons, "QP_CMD"), -1);

    /* No hidden state: a second load of the same module in the same process is the same. */
    ske_module_cfg_t *m2 = NULL;
    CHECK_EQ(ske_config_load(EXAMPLE, &no_resolve, &m2, &d), SKE_OK);
    if (m2) {
        CHECK_EQ(m2->n_windows, 4);
        CHECK_EQ(m2->partitions[1].period_anchor_ns, 10000000);
    }
    ske_config_free(m2);
    ske_config_free(m);
    free(text);
}

/* Periods shorter than the major frame, anchors, argument splitting, the extension element,
 * summed memory, and the lookup of executables. */
static const char details_xml[] =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<ARINC_653_Module xmlns:ima=\"urn:ima-testbed:arinc653-linux:1\" ModuleName=\"details\">\n"
    "  <ima:Module_Extension Node=\"nodeX\" TimeMode=\"realtime\"/>\n"
    "  <Partition PartitionIdentifier=\"10\" PartitionName=\"fast\" SystemPartition=\"true\">\n"
    "    <ima:Linux Executable=\"fast_prog\" Arguments=\"--rate 50   -v\"/>\n"
    "  </Partition>\n"
    "  <Partition PartitionIdentifier=\"20\" PartitionName=\"slow\" Criticality=\"LEVEL_A\">\n"
    "    <ima:Linux Executable=\"bin/slow_prog\"/>\n"
    "  </Partition>\n"
    "  <Partition PartitionIdentifier=\"30\" PartitionName=\"mid\">\n"
    "    <ima:Linux Executable=\"fast_prog\"/>\n"
    "  </Partition>\n"
    "  <Partition_Memory PartitionIdentifier=\"20\" PartitionName=\"slow\">\n"
    "    <Memory_Requirements SizeBytes=\"4096\"/>\n"
    "    <Memory_Requirements Type=\"CODE\" SizeBytes=\"0x1000\"/>\n"
    "  </Partition_Memory>\n"
    "  <Module_Schedule MajorFrameSeconds=\"0.1\">\n"
    "    <Partition_Schedule PartitionIdentifier=\"30\" PartitionName=\"mid\" PeriodSeconds=\"0.05\">\n"
    "      <Window_Schedule WindowIdentifier=\"6\" WindowStartSeconds=\"0.085\" WindowDurationSeconds=\"0.01\"/>\n"
    "      <Window_Schedule WindowIdentifier=\"5\" WindowStartSeconds=\"0.035\" WindowDurationSeconds=\"0.01\" PartitionPeriodStart=\"true\"/>\n"
    "    </Partition_Schedule>\n"
    "    <Partition_Schedule PartitionIdentifier=\"10\" PartitionName=\"fast\" PeriodSeconds=\"0.05\" PeriodDurationSeconds=\"0.01\">\n"
    "      <Window_Schedule WindowIdentifier=\"1\" WindowStartSeconds=\"0\" WindowDurationSeconds=\"0.01\"/>\n"
    "      <Window_Schedule WindowIdentifier=\"2\" WindowStartSeconds=\"0.05\" WindowDurationSeconds=\"0.01\"/>\n"
    "    </Partition_Schedule>\n"
    "    <Partition_Schedule PartitionIdentifier=\"20\" PartitionName=\"slow\" PeriodSeconds=\"0.1\">\n"
    "      <Window_Schedule WindowIdentifier=\"4\" WindowStartSeconds=\"0.07\" WindowDurationSeconds=\"0.005\"/>\n"
    "      <Window_Schedule WindowIdentifier=\"3\" WindowStartSeconds=\"0.02\" WindowDurationSeconds=\"0.01\"/>\n"
    "    </Partition_Schedule>\n"
    "  </Module_Schedule>\n"
    "</ARINC_653_Module>\n";

static void test_load_schedule_and_extension(void)
{
    const char *path = write_module("details.xml", details_xml);
    REQUIRE(path);
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_OK);
    REQUIRE(m);
    CHECK_STR(m->node, "nodeX");
    CHECK_EQ(m->time_mode, SKE_TIME_REALTIME);
    CHECK_EQ(m->major_frame_ns, 100000000);
    CHECK_EQ(m->n_channels, 0);
    REQUIRE(m->n_partitions == 3);
    const ske_partition_cfg_t *fast = &m->partitions[0], *slow = &m->partitions[1],
                              *mid = &m->partitions[2];

    CHECK(fast->system_partition);
    CHECK_STR(fast->criticality, "LEVEL_E"); /* the default */
    CHECK_STR(fast->entry_point, "");
    CHECK_EQ(fast->argc, 4);
    CHECK_STR(fast->argv[0], "fast");
    CHECK_STR(fast->argv[1], "--rate");
    CHECK_STR(fast->argv[2], "50");
    CHECK_STR(fast->argv[3], "-v");
    CHECK(fast->argv[4] == NULL);
    CHECK_EQ(fast->period_ns, 50000000);
    CHECK_EQ(fast->duration_ns, 10000000); /* per period, not per major frame */
    CHECK_EQ(fast->period_anchor_ns, 0);
    CHECK_EQ(fast->n_windows, 2);
    CHECK_EQ_U(fast->memory_bytes, 0); /* none declared */

    CHECK(!slow->system_partition);
    CHECK_STR(slow->criticality, "LEVEL_A");
    CHECK_EQ(slow->argc, 1);
    CHECK_EQ(slow->period_ns, 100000000);
    CHECK_EQ(slow->duration_ns, 15000000);
    /* No PartitionPeriodStart: the earliest window starts the period, not the first listed. */
    CHECK_EQ(slow->period_anchor_ns, 20000000);
    CHECK_EQ_U(slow->memory_bytes, 8192); /* 4096 + 0x1000 */

    CHECK_EQ(mid->period_ns, 50000000);
    CHECK_EQ(mid->duration_ns, 10000000);
    CHECK_EQ(mid->period_anchor_ns, 35000000);

    static const int32_t order[] = {1, 3, 5, 2, 4, 6};
    static const int64_t offsets[] = {0, 20000000, 35000000, 50000000, 70000000, 85000000};
    static const int owner[] = {0, 1, 2, 0, 1, 2};
    CHECK_EQ(m->n_windows, 6);
    for (int i = 0; i < 6 && i < m->n_windows; i++) {
        CHECK_EQ(m->windows[i].id, order[i]);
        CHECK_EQ(m->windows[i].offset_ns, offsets[i]);
        CHECK_EQ(m->windows[i].partition, owner[i]);
        CHECK_EQ(m->windows[i].period_start, order[i] == 5);
    }
    ske_config_free(m);
}

static void test_resolve_executables(void)
{
    char dir[PATH_MAX], prog[PATH_MAX], want_fast[PATH_MAX], want_slow[PATH_MAX];
    char ppath[2 * PATH_MAX];
    /* A bare name is searched along the partition path, skipping files that are not
     * executable; a name with a slash is relative to the module's folder. */
    snprintf(dir, sizeof dir, "%s/path_noexec", tmp_dir);
    REQUIRE(mkdir(dir, 0755) == 0);
    snprintf(prog, sizeof prog, "%s/path_noexec/fast_prog", tmp_dir);
    REQUIRE(write_file(prog, "#!/bin/sh\n", 0644));
    snprintf(dir, sizeof dir, "%s/path", tmp_dir);
    REQUIRE(mkdir(dir, 0755) == 0);
    snprintf(want_fast, sizeof want_fast, "%s/path/fast_prog", tmp_dir);
    REQUIRE(write_file(want_fast, "#!/bin/sh\n", 0755));
    snprintf(dir, sizeof dir, "%s/bin", tmp_dir);
    REQUIRE(mkdir(dir, 0755) == 0);
    snprintf(want_slow, sizeof want_slow, "%s/bin/slow_prog", tmp_dir);
    REQUIRE(write_file(want_slow, "#!/bin/sh\n", 0755));
    const char *path = write_module("details.xml", details_xml);
    REQUIRE(path);

    snprintf(ppath, sizeof ppath, "/nonexistent/ske_test:%s/path_noexec:%s/path", tmp_dir, tmp_dir);
    ske_load_opts_t opts = {.schema_dir = SCHEMA_DIR, .partition_path = ppath,
                            .resolve_executables = true};
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    CHECK_EQ(ske_config_load(path, &opts, &m, &d), SKE_OK);
    REQUIRE(m);
    char real_fast[PATH_MAX], real_slow[PATH_MAX];
    REQUIRE(realpath(want_fast, real_fast) && realpath(want_slow, real_slow));
    CHECK_STR(m->partitions[0].executable, real_fast);
    CHECK_STR(m->partitions[1].executable, real_slow);
    CHECK_STR(m->partitions[2].executable, real_fast);
    CHECK_STR(m->partitions[1].exe_name, "bin/slow_prog"); /* as written */
    ske_config_free(m);

    /* Not found: the diagnostic names the partition, the program and where it looked. */
    snprintf(ppath, sizeof ppath, "%s/path_noexec", tmp_dir);
    m = (ske_module_cfg_t *)&d; /* any non-NULL value: a failed load must reset it */
    CHECK_EQ(ske_config_load(path, &opts, &m, &d), SKE_E_CONFIG);
    CHECK(m == NULL);
    CHECK_STR(d.file, path);
    CHECK_EQ(d.line, line_of(details_xml, "<Partition PartitionIdentifier=\"10\""));
    CHECK_STR(d.element, "Partition");
    CHECK_STR(d.rule, "the partition's program exists");
    CHECK_CONTAINS(d.message, "'fast'");
    CHECK_CONTAINS(d.message, "'fast_prog'");
    CHECK_CONTAINS(d.message, ppath);

    /* The relative one, with the bare ones found. */
    snprintf(ppath, sizeof ppath, "%s/path", tmp_dir);
    unlink(want_slow);
    CHECK_EQ(ske_config_load(path, &opts, &m, &d), SKE_E_CONFIG);
    CHECK_EQ(d.line, line_of(details_xml, "<Partition PartitionIdentifier=\"20\""));
    CHECK_CONTAINS(d.message, "'slow'");
    CHECK_CONTAINS(d.message, "'bin/slow_prog'");
}

/* ---- invalid modules ------------------------------------------------------------------ */

/* A small valid module, one start tag per line, that each case below breaks in one place. */
static const char base_xml[] =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<ARINC_653_Module xmlns:ima=\"urn:ima-testbed:arinc653-linux:1\" ModuleName=\"unit\">\n"
    "  <Partition PartitionIdentifier=\"1\" PartitionName=\"p1\">\n"
    "    <Sampling_Port Name=\"S_OUT\" MaxMessageSize=\"16\" Direction=\"SOURCE\" RefreshRateSeconds=\"0.1\"/>\n"
    "    <Queuing_Port Name=\"Q_OUT\" MaxMessageSize=\"8\" Direction=\"SOURCE\" MaxNbMessages=\"4\"/>\n"
    "    <ima:Linux Executable=\"p1\"/>\n"
    "  </Partition>\n"
    "  <Partition PartitionIdentifier=\"2\" PartitionName=\"p2\">\n"
    "    <Sampling_Port Name=\"S_IN\" MaxMessageSize=\"16\" Direction=\"DESTINATION\" RefreshRateSeconds=\"0.1\"/>\n"
    "    <Queuing_Port Name=\"Q_IN\" MaxMessageSize=\"8\" Direction=\"DESTINATION\" MaxNbMessages=\"4\"/>\n"
    "    <ima:Linux Executable=\"p2\"/>\n"
    "  </Partition>\n"
    "  <Module_Schedule MajorFrameSeconds=\"0.02\">\n"
    "    <Partition_Schedule PartitionIdentifier=\"1\" PartitionName=\"p1\" PeriodSeconds=\"0.02\">\n"
    "      <Window_Schedule WindowIdentifier=\"1\" WindowStartSeconds=\"0\" WindowDurationSeconds=\"0.01\"/>\n"
    "    </Partition_Schedule>\n"
    "    <Partition_Schedule PartitionIdentifier=\"2\" PartitionName=\"p2\" PeriodSeconds=\"0.02\">\n"
    "      <Window_Schedule WindowIdentifier=\"2\" WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"/>\n"
    "    </Partition_Schedule>\n"
    "  </Module_Schedule>\n"
    "  <Connection_Table>\n"
    "    <Channel ChannelIdentifier=\"1\" ChannelName=\"s\">\n"
    "      <Source><Standard_Partition PartitionIdentifier=\"1\" PartitionName=\"p1\" PortName=\"S_OUT\"/></Source>\n"
    "      <Destination><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"S_IN\"/></Destination>\n"
    "    </Channel>\n"
    "    <Channel ChannelIdentifier=\"2\" ChannelName=\"q\">\n"
    "      <Source><Standard_Partition PartitionIdentifier=\"1\" PartitionName=\"p1\" PortName=\"Q_OUT\"/></Source>\n"
    "      <Destination><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"Q_IN\"/></Destination>\n"
    "    </Channel>\n"
    "  </Connection_Table>\n"
    "</ARINC_653_Module>\n";

#define P2_SCHEDULE                                                                             \
    "    <Partition_Schedule PartitionIdentifier=\"2\" PartitionName=\"p2\" PeriodSeconds=\"0.02\">\n" \
    "      <Window_Schedule WindowIdentifier=\"2\" WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"/>\n" \
    "    </Partition_Schedule>\n"
#define S_IN_PORT                                                                               \
    "    <Sampling_Port Name=\"S_IN\" MaxMessageSize=\"16\" Direction=\"DESTINATION\" RefreshRateSeconds=\"0.1\"/>\n"
#define S_OUT_PORT                                                                              \
    "    <Sampling_Port Name=\"S_OUT\" MaxMessageSize=\"16\" Direction=\"SOURCE\" RefreshRateSeconds=\"0.1\"/>\n"
#define Q_IN_PORT                                                                               \
    "    <Queuing_Port Name=\"Q_IN\" MaxMessageSize=\"8\" Direction=\"DESTINATION\" MaxNbMessages=\"4\"/>\n"
#define Q_CHANNEL_DST                                                                           \
    "      <Destination><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"Q_IN\"/></Destination>\n"
#define CONNECTION_TABLE "  <Connection_Table>\n"

typedef struct {
    const char *name;
    const char *from, *to; /* substitutions in base_xml (from2 may be NULL) */
    const char *from2, *to2;
    const char *at; /* text on the line the diagnostic names */
    const char *element;
    const char *rule; /* NULL: any rule (the schema's wording, see the known defects) */
    const char *says[2]; /* fragments of the message */
} bad_case_t;

static const bad_case_t bad_cases[] = {
    {"windows overlap",
     "WindowIdentifier=\"2\" WindowStartSeconds=\"0.01\"", "WindowIdentifier=\"2\" WindowStartSeconds=\"0.005\"",
     NULL, NULL, "WindowIdentifier=\"2\"", "Window_Schedule",
     "windows of a module schedule do not overlap", {"overlaps window 1", "partition 'p1'"}},
    {"window past the major frame",
     "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"", "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.010000001\"",
     NULL, NULL, "WindowIdentifier=\"2\"", "Window_Schedule",
     "windows end within the major frame", {"past the major frame", "20000001"}},
    {"window of zero duration",
     "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"", "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0\"",
     NULL, NULL, "WindowIdentifier=\"2\"", "Window_Schedule",
     "windows have a positive duration", {"WindowDurationSeconds", NULL}},
    {"duplicate window identifier",
     "WindowIdentifier=\"2\"", "WindowIdentifier=\"1\"", NULL, NULL,
     "WindowStartSeconds=\"0.01\"", "Window_Schedule", "window identifiers are unique",
     {"WindowIdentifier=1", NULL}},
    {"zero major frame",
     "MajorFrameSeconds=\"0.02\"", "MajorFrameSeconds=\"0\"", NULL, NULL,
     "<Module_Schedule", "Module_Schedule", "the major frame is positive", {"MajorFrameSeconds", NULL}},
    {"duration that passes the schema but overflows",
     "MajorFrameSeconds=\"0.02\"", "MajorFrameSeconds=\"99999999999\"", NULL, NULL,
     "<Module_Schedule", "Module_Schedule", "durations are decimal seconds",
     {"MajorFrameSeconds='99999999999'", NULL}},
    {"schedule names an unknown partition",
     "<Partition_Schedule PartitionIdentifier=\"2\"", "<Partition_Schedule PartitionIdentifier=\"7\"",
     NULL, NULL, "<Partition_Schedule PartitionIdentifier=\"7\"", "Partition_Schedule",
     "references name a declared Partition", {"PartitionIdentifier=7", NULL}},
    {"schedule identifier and name disagree",
     "<Partition_Schedule PartitionIdentifier=\"2\" PartitionName=\"p2\"",
     "<Partition_Schedule PartitionIdentifier=\"2\" PartitionName=\"p1\"", NULL, NULL,
     "<Partition_Schedule PartitionIdentifier=\"2\"", "Partition_Schedule",
     "PartitionIdentifier and PartitionName name the same partition", {"'p2'", "'p1'"}},
    {"second schedule for a partition",
     "<Partition_Schedule PartitionIdentifier=\"2\" PartitionName=\"p2\"",
     "<Partition_Schedule PartitionIdentifier=\"1\" PartitionName=\"p1\"", NULL, NULL,
     "<Partition_Schedule PartitionIdentifier=\"1\" PartitionName=\"p1\" PeriodSeconds=\"0.02\">\n"
     "      <Window_Schedule WindowIdentifier=\"2\"",
     "Partition_Schedule", "one Partition_Schedule per partition",
     {"'p1'", NULL}},
    {"partition without a window", P2_SCHEDULE, "", NULL, NULL,
     "<Partition PartitionIdentifier=\"2\"", "Partition", "every partition has at least one window",
     {"'p2' has no window", NULL}},
    {"period does not divide the major frame",
     "PartitionName=\"p2\" PeriodSeconds=\"0.02\"", "PartitionName=\"p2\" PeriodSeconds=\"0.015\"",
     NULL, NULL, "<Partition_Schedule PartitionIdentifier=\"2\"", "Partition_Schedule",
     "the partition period divides the major frame", {"15000000 ns", "20000000 ns"}},
    {"PeriodDurationSeconds disagrees with the windows",
     "PartitionName=\"p2\" PeriodSeconds=\"0.02\"",
     "PartitionName=\"p2\" PeriodSeconds=\"0.02\" PeriodDurationSeconds=\"0.005\"", NULL, NULL,
     "<Partition_Schedule PartitionIdentifier=\"2\"", "Partition_Schedule",
     "PeriodDurationSeconds is the window time per period", {"5000000 ns", "10000000 ns"}},
    {"memory of an unknown partition",
     "  <Module_Schedule",
     "  <Partition_Memory PartitionIdentifier=\"9\" PartitionName=\"p9\"><Memory_Requirements SizeBytes=\"4096\"/></Partition_Memory>\n"
     "  <Module_Schedule", NULL, NULL,
     "<Partition_Memory", "Partition_Memory", "references name a declared Partition",
     {"PartitionIdentifier=9", NULL}},
    {"duplicate partition identifier",
     "<Partition PartitionIdentifier=\"2\" PartitionName=\"p2\">",
     "<Partition PartitionIdentifier=\"1\" PartitionName=\"p2\">", NULL, NULL,
     "PartitionName=\"p2\">", "Partition", "partition identifiers are unique",
     {"PartitionIdentifier=1", "'p1'"}},
    {"duplicate partition name",
     "<Partition PartitionIdentifier=\"2\" PartitionName=\"p2\">",
     "<Partition PartitionIdentifier=\"2\" PartitionName=\"p1\">", NULL, NULL,
     "<Partition PartitionIdentifier=\"2\"", "Partition", "partition names are unique", {"'p1'", NULL}},
    {"duplicate port name", "<Queuing_Port Name=\"Q_IN\"", "<Queuing_Port Name=\"S_IN\"", NULL, NULL,
     "<Queuing_Port Name=\"S_IN\"", "Queuing_Port", "port names are unique within a partition",
     {"'S_IN'", NULL}},
    {"channel ports differ in size",
     "Name=\"S_IN\" MaxMessageSize=\"16\"", "Name=\"S_IN\" MaxMessageSize=\"32\"", NULL, NULL,
     "PortName=\"S_IN\"/></Destination>", "Destination",
     "the ports of a channel have the same MaxMessageSize",
     {"MaxMessageSize=16", "has 32"}},
    {"channel source is a DESTINATION port",
     "<Source><Standard_Partition PartitionIdentifier=\"1\" PartitionName=\"p1\" PortName=\"S_OUT\"/></Source>",
     "<Source><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"S_IN\"/></Source>",
     NULL, NULL, "PortName=\"S_IN\"/></Source>", "Source", "a channel's Source is a SOURCE port",
     {"'S_IN'", "DESTINATION port"}},
    {"channel destination is a SOURCE port",
     S_IN_PORT, S_IN_PORT "    <Sampling_Port Name=\"S_BACK\" MaxMessageSize=\"16\" Direction=\"SOURCE\" RefreshRateSeconds=\"0.1\"/>\n",
     "PortName=\"S_IN\"/></Destination>", "PortName=\"S_BACK\"/></Destination>",
     "PortName=\"S_BACK\"/></Destination>", "Destination",
     "a channel's Destination is a DESTINATION port",
     {"'S_BACK'", "SOURCE port"}},
    {"channel names an undeclared port",
     "PortName=\"S_IN\"/></Destination>", "PortName=\"S_NONE\"/></Destination>", NULL, NULL,
     "PortName=\"S_NONE\"", "Standard_Partition", "a channel connects ports that partitions declare",
     {"'S_NONE'", "'p2'"}},
    {"queuing channel with two destinations",
     Q_IN_PORT, Q_IN_PORT "    <Queuing_Port Name=\"Q_IN2\" MaxMessageSize=\"8\" Direction=\"DESTINATION\" MaxNbMessages=\"4\"/>\n",
     Q_CHANNEL_DST, Q_CHANNEL_DST "      <Destination><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"Q_IN2\"/></Destination>\n",
     "ChannelName=\"q\"", "Channel", "a queuing channel has exactly one destination",
     {"2 destinations", NULL}},
    {"sampling channel to a queuing port",
     "PortName=\"S_IN\"/></Destination>", "PortName=\"Q_IN\"/></Destination>", NULL, NULL,
     "PortName=\"Q_IN\"/></Destination>", "Destination", "a channel connects ports of one kind",
     {"sampling port 'S_OUT'", "queuing port 'Q_IN'"}},
    {"port in two channels",
     S_OUT_PORT, S_OUT_PORT "    <Sampling_Port Name=\"S_OUT2\" MaxMessageSize=\"16\" Direction=\"SOURCE\" RefreshRateSeconds=\"0.1\"/>\n",
     "  </Connection_Table>",
     "    <Channel ChannelIdentifier=\"3\" ChannelName=\"s2\">\n"
     "      <Source><Standard_Partition PartitionIdentifier=\"1\" PartitionName=\"p1\" PortName=\"S_OUT2\"/></Source>\n"
     "      <Destination><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"S_IN\"/></Destination>\n"
     "    </Channel>\n"
     "  </Connection_Table>",
     "S_IN\"/></Destination>\n    </Channel>\n  </Connection_Table>", "Destination",
     "a port belongs to one channel", {"'S_IN'", "channel 's'"}},
    {"duplicate channel identifier", "ChannelIdentifier=\"2\"", "ChannelIdentifier=\"1\"", NULL, NULL,
     "ChannelName=\"q\"", "Channel", "channel identifiers are unique", {"ChannelIdentifier=1", NULL}},
    {"sampling port refreshed never",
     "Name=\"S_OUT\" MaxMessageSize=\"16\" Direction=\"SOURCE\" RefreshRateSeconds=\"0.1\"",
     "Name=\"S_OUT\" MaxMessageSize=\"16\" Direction=\"SOURCE\" RefreshRateSeconds=\"0\"", NULL, NULL,
     "Name=\"S_OUT\"", "Sampling_Port", "RefreshRateSeconds is positive",
     {"RefreshRateSeconds must be greater than 0", NULL}},
    {"queuing port over 64 MiB",
     "Name=\"Q_OUT\" MaxMessageSize=\"8\" Direction=\"SOURCE\" MaxNbMessages=\"4\"",
     "Name=\"Q_OUT\" MaxMessageSize=\"1048576\" Direction=\"SOURCE\" MaxNbMessages=\"65\"",
     NULL, NULL, "Name=\"Q_OUT\"", "Queuing_Port", "a queuing port holds at most 64 MiB",
     {"MaxNbMessages=65 of 1048576 bytes needs 65 MiB", NULL}},
    {"too many arguments", "<ima:Linux Executable=\"p2\"/>",
     "<ima:Linux Executable=\"p2\" Arguments=\"a b c d e f g h i j k l m n o p q r s t u v w x y z "
     "A B C D E\"/>", NULL, NULL, "Executable=\"p2\"", "Linux", "at most 30 arguments",
     {"too many Arguments for partition 'p2'", NULL}},
    /* start tags split over lines: the diagnostic names the line where the tag begins,
     * whatever follows the element's name (a tab, a newline, CR LF) and with a prefix */
    {"windows overlap, a tab after the name", "<Window_Schedule WindowIdentifier=\"2\" WindowStartSeconds=\"0.01\"",
     "<Window_Schedule\tWindowIdentifier=\"2\"\n        WindowStartSeconds=\"0.005\"", NULL, NULL,
     "<Window_Schedule\tWindowIdentifier=\"2\"", "Window_Schedule",
     "windows of a module schedule do not overlap", {"overlaps window 1", NULL}},
    {"windows overlap, a newline after the name", "<Window_Schedule WindowIdentifier=\"2\" WindowStartSeconds=\"0.01\"",
     "<Window_Schedule\n        WindowIdentifier=\"2\" WindowStartSeconds=\"0.005\"", NULL, NULL,
     "<Window_Schedule\n", "Window_Schedule",
     "windows of a module schedule do not overlap", {"overlaps window 1", NULL}},
    {"windows overlap, CR LF after the name", "<Window_Schedule WindowIdentifier=\"2\" WindowStartSeconds=\"0.01\"",
     "<Window_Schedule\r\n        WindowIdentifier=\"2\" WindowStartSeconds=\"0.005\"", NULL, NULL,
     "<Window_Schedule\r\n", "Window_Schedule",
     "windows of a module schedule do not overlap", {"overlaps window 1", NULL}},
    {"too many arguments, the tag over two lines", "<ima:Linux Executable=\"p2\"/>",
     "<ima:Linux\n      Executable=\"p2\" Arguments=\"a b c d e f g h i j k l m n o p q r s t u v w x y z "
     "A B C D E\"/>", NULL, NULL, "<ima:Linux\n", "Linux", "at most 30 arguments",
     {"too many Arguments for partition 'p2'", NULL}},
    {"partition without a program", "<ima:Linux Executable=\"p2\"/>", "", NULL, NULL,
     "<Partition PartitionIdentifier=\"2\"", "Partition", "each Partition has an ima:Linux element",
     {"partition 'p2' does not say which program runs it", NULL}},
    {"empty module name", "ModuleName=\"unit\"", "ModuleName=\"\"", NULL, NULL,
     "<ARINC_653_Module", "ARINC_653_Module", "a module name of 1 to 63 characters",
     {"ModuleName is empty", NULL}},
    {"HM log port that is not its own", "<ima:Linux Executable=\"p2\"/>",
     "<ima:Linux Executable=\"p2\" HealthMonitorLogPort=\"HM_LOG\"/>", NULL, NULL,
     "<Partition PartitionIdentifier=\"2\"", "Partition",
     "the health-monitor log port is one of the partition's destination queuing ports, on no "
     "channel, of at least the size of a decision",
     {"HealthMonitorLogPort 'HM_LOG' is not one of its ports", NULL}},
    {"HM log port on a channel", "<ima:Linux Executable=\"p2\"/>",
     "<ima:Linux Executable=\"p2\" HealthMonitorLogPort=\"Q_IN\"/>", NULL, NULL,
     "<Queuing_Port Name=\"Q_IN\"", "Queuing_Port",
     "the health-monitor log port is one of the partition's destination queuing ports, on no "
     "channel, of at least the size of a decision",
     {"HealthMonitorLogPort 'Q_IN' must be a destination queuing port on no channel", NULL}},
    {"HM log port that is a sampling port", "<ima:Linux Executable=\"p2\"/>",
     "<ima:Linux Executable=\"p2\" HealthMonitorLogPort=\"S_IN\"/>", NULL, NULL,
     "<Sampling_Port Name=\"S_IN\"", "Queuing_Port", NULL,
     {"HealthMonitorLogPort 'S_IN' must be a destination queuing port", NULL}},
    {"document type declaration", "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n",
     "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!DOCTYPE ARINC_653_Module>\n", NULL, NULL,
     "<!DOCTYPE", "", "no document type declaration", {"DOCTYPE", NULL}},
    {"channel source used twice",
     "<Source><Standard_Partition PartitionIdentifier=\"1\" PartitionName=\"p1\" PortName=\"Q_OUT\"/></Source>",
     "<Source><Standard_Partition PartitionIdentifier=\"1\" PartitionName=\"p1\" PortName=\"S_OUT\"/></Source>",
     NULL, NULL, "PortName=\"S_OUT\"/></Source>\n      <Destination><Standard_Partition PartitionIdentifier=\"2\" PartitionName=\"p2\" PortName=\"Q_IN\"",
     "Source", "a port belongs to one channel", {"'S_OUT'", "already the source of channel 's'"}},
    {"identifier past its range", "<Partition PartitionIdentifier=\"2\" PartitionName=\"p2\">",
     "<Partition PartitionIdentifier=\"3000000000\" PartitionName=\"p2\">", NULL, NULL,
     "PartitionIdentifier=\"3000000000\"", "Partition", "numbers are within their range",
     {"PartitionIdentifier='3000000000' is too large: at most 2147483647", NULL}},
    {"malformed stack size", "<ima:Linux Executable=\"p2\"/>",
     "<Process Name=\"w\" StackSize=\"64k\"/>\n    <ima:Linux Executable=\"p2\"/>", NULL, NULL,
     "StackSize=\"64k\"", "Process", "numbers are positive integers",
     {"StackSize='64k' is not a valid number", "(decimal or 0x-hexadecimal)"}},
    {"malformed memory size", "  <Module_Schedule",
     "  <Partition_Memory PartitionIdentifier=\"2\" PartitionName=\"p2\"><Memory_Requirements SizeBytes=\"32MB\"/></Partition_Memory>\n"
     "  <Module_Schedule", NULL, NULL,
     "SizeBytes=\"32MB\"", "Memory_Requirements", "numbers are positive integers",
     {"SizeBytes='32MB' is not a valid number", "(decimal or 0x-hexadecimal)"}},
    {"not well-formed", "</Connection_Table>", "</Connection_Tabel>", NULL, NULL,
     "</Connection_Tabel>", "", "well-formed XML", {"Connection_Table", NULL}},
    {"unknown element", "<ima:Linux Executable=\"p2\"/>", "<Bogus/>\n    <ima:Linux Executable=\"p2\"/>",
     NULL, NULL, "<Bogus/>", "Bogus", "schema ima653_module.xsd", {"Bogus", "not expected"}},
    {"malformed number", "Name=\"Q_OUT\" MaxMessageSize=\"8\"", "Name=\"Q_OUT\" MaxMessageSize=\"12x\"",
     NULL, NULL, "\"12x\"", "Queuing_Port", NULL, {"MaxMessageSize", "12x"}},
    {"malformed duration abc", "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"",
     "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"abc\"", NULL, NULL,
     "\"abc\"", "Window_Schedule", NULL, {"WindowDurationSeconds", "abc"}},
    {"malformed duration 1e-3", "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"",
     "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"1e-3\"", NULL, NULL,
     "\"1e-3\"", "Window_Schedule", NULL, {"WindowDurationSeconds", "1e-3"}},
    {"negative duration", "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"",
     "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"-0.01\"", NULL, NULL,
     "\"-0.01\"", "Window_Schedule", NULL, {"WindowDurationSeconds", "-0.01"}},
    {"duration below the nanosecond", "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"",
     "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.0000000001\"", NULL, NULL,
     "\"0.0000000001\"", "Window_Schedule", NULL, {"WindowDurationSeconds", "0.0000000001"}},
};

static void check_bad_case(const bad_case_t *c)
{
    char *t1 = replace_once(base_xml, c->from, c->to);
    char *text = t1 && c->from2 ? replace_once(t1, c->from2, c->to2) : t1;
    if (!text) {
        fprintf(stderr, "  case '%s': its substitution does not apply once\n", c->name);
        ske_test_failures++;
        goto out;
    }
    const char *path = write_module("bad.xml", text);
    if (!path) {
        ske_test_failures++;
        goto out;
    }
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    int rc = ske_config_load(path, &no_resolve, &m, &d);
    char line[2048];
    ske_diag_format(&d, line, sizeof line);
    int failures = ske_test_failures;
    CHECK_EQ(rc, SKE_E_CONFIG);
    CHECK(m == NULL);
    CHECK_STR(d.file, path);
    CHECK_EQ(d.line, line_of(text, c->at));
    CHECK_STR(d.element, c->element);
    if (c->rule)
        CHECK_STR(d.rule, c->rule);
    else
        CHECK(d.rule[0] != '\0');
    for (int i = 0; i < 2; i++)
        if (c->says[i])
            CHECK_CONTAINS(d.message, c->says[i]);
    /* The one line the user sees: "FILE:LINE: error: ELEMENT: message (rule: ...)". */
    char prefix[PATH_MAX + 128];
    snprintf(prefix, sizeof prefix, "%s:%d: error: %s%s", path, line_of(text, c->at), c->element,
             c->element[0] ? ": " : "");
    CHECK(strncmp(line, prefix, strlen(prefix)) == 0);
    CHECK(strchr(line, '\n') == NULL);
    if (c->element[0]) {
        char rule[256];
        snprintf(rule, sizeof rule, "(rule: %s)", d.rule);
        CHECK_CONTAINS(line, rule);
    }
    if (ske_test_failures != failures)
        fprintf(stderr, "  in case '%s': %s\n", c->name, line);
    ske_config_free(m);
out:
    if (text != t1)
        free(text);
    free(t1);
}

/* base_xml with `extra` inserted once before `before`; NULL if that does not apply. */
static char *with_inserted(const char *before, const char *extra)
{
    size_t n = strlen(before) + strlen(extra) + 1;
    char *to = malloc(n);
    if (!to)
        return NULL;
    snprintf(to, n, "%s%s", extra, before);
    char *text = replace_once(base_xml, before, to);
    free(to);
    return text;
}

/* Tables of fixed size: one element too many is named, with its place. */
static void test_limits(void)
{
    static char extra[1 << 16];
    size_t n = 0;
    for (int i = 0; i < 64; i++) /* p1 has two ports already */
        n += (size_t)snprintf(extra + n, sizeof extra - n,
                              "    <Sampling_Port Name=\"X%d\" MaxMessageSize=\"8\" "
                              "Direction=\"SOURCE\" RefreshRateSeconds=\"1\"/>\n", i);
    char *text = with_inserted("    <ima:Linux Executable=\"p1\"/>", extra);
    REQUIRE(text);
    const char *path = write_module("ports.xml", text);
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_E_CONFIG);
    CHECK_STR(d.rule, "at most 64 ports per partition");
    CHECK_CONTAINS(d.message, "too many ports in partition 'p1'");
    CHECK_EQ(d.line, line_of(text, "Name=\"X62\""));
    free(text);

    n = 0;
    for (int i = 3; i <= 33; i++) /* two already */
        n += (size_t)snprintf(extra + n, sizeof extra - n,
                              "  <Partition PartitionIdentifier=\"%d\" PartitionName=\"p%d\">\n"
                              "    <ima:Linux Executable=\"p\"/>\n  </Partition>\n", i, i);
    text = with_inserted("  <Module_Schedule", extra);
    REQUIRE(text);
    path = write_module("partitions.xml", text);
    CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_E_CONFIG);
    CHECK_CONTAINS(d.message, "too many partitions");
    CHECK_EQ(d.line, line_of(text, "PartitionName=\"p33\""));
    free(text);
}

static void test_base_module_is_valid(void)
{
    const char *path = write_module("base.xml", base_xml);
    REQUIRE(path);
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_OK);
    if (m) {
        CHECK_EQ(m->n_partitions, 2);
        CHECK_EQ(m->n_windows, 2);
        CHECK_EQ(m->n_channels, 2);
    }
    ske_config_free(m);
}

static void test_invalid_modules(void)
{
    for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; i++)
        check_bad_case(&bad_cases[i]);
}

static void test_unreadable_inputs(void)
{
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/no_such_module.xml", tmp_dir);
    CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_E_IO);
    CHECK(m == NULL);
    CHECK_STR(d.file, path);
    CHECK_CONTAINS(d.message, "cannot read");

    ske_load_opts_t no_schema = {.schema_dir = "/nonexistent/ske_test_schema"};
    CHECK_EQ(ske_config_load(EXAMPLE, &no_schema, &m, &d), SKE_E_IO);
    CHECK(m == NULL);
    CHECK_CONTAINS(d.file, "/nonexistent/ske_test_schema");
    CHECK_CONTAINS(d.message, "schema");
}

static void test_diag_format(void)
{
    ske_diag_t d = {.file = "m.xml", .line = 12, .element = "Channel", .message = "bad thing",
                    .rule = "some rule"};
    char buf[256];
    ske_diag_format(&d, buf, sizeof buf);
    CHECK_STR(buf, "m.xml:12: error: Channel: bad thing (rule: some rule)");
    d.rule[0] = '\0';
    ske_diag_format(&d, buf, sizeof buf);
    CHECK_STR(buf, "m.xml:12: error: Channel: bad thing");
    d.element[0] = '\0';
    ske_diag_format(&d, buf, sizeof buf);
    CHECK_STR(buf, "m.xml:12: error: bad thing");
    /* A short buffer gets a truncated, terminated line. */
    char small[8];
    memset(small, 'x', sizeof small);
    ske_diag_format(&d, small, sizeof small);
    CHECK_STR(small, "m.xml:1");
}

/* A diagnostic is one line: the control characters of what it quotes of the input become one
 * space per run, none leads or trails; missing names become empty fields. */
static void test_diag_set(void)
{
    ske_diag_t d;
    ske__diag_set(&d, NULL, 3, NULL, NULL, "%s", "\n\tbad\r\n\x7fthing\n\n");
    CHECK_STR(d.file, "?");
    CHECK_STR(d.element, "");
    CHECK_STR(d.rule, "");
    CHECK_STR(d.message, "bad thing");
    ske__diag_set(&d, "m.xml", 4, "Channel", "a rule", "%s", "\n\n");
    CHECK_STR(d.message, "");
    char buf[256];
    d.element[0] = '\0';
    ske__diag_set(&d, "m.xml", 4, NULL, "a rule", "%s", "no element");
    ske_diag_format(&d, buf, sizeof buf);
    CHECK_STR(buf, "m.xml:4: error: no element (rule: a rule)");
}

/* ---- regressions: defects found and fixed, checked on every run ------------------------ */

/* A diagnostic names the line where the element starts. libxml2 records the line where the
 * start tag ends, so an element whose attributes span two lines is reported one line late. */
static void defect_line_of_multiline_start_tag(void)
{
    char *text = read_text(EXAMPLE);
    REQUIRE(text);
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    CHECK_EQ(ske_config_load(EXAMPLE, &no_resolve, &m, &d), SKE_OK);
    if (m) {
        CHECK_EQ(m->partitions[0].line, line_of(text, "<Partition PartitionIdentifier=\"1\""));
        CHECK_EQ(m->windows[0].line, line_of(text, "<Window_Schedule WindowIdentifier=\"1\""));
    }
    ske_config_free(m);
    free(text);
}

/* A malformed number or duration caught by the schema gets the same rule and wording as one
 * caught by the loader ("durations are decimal seconds"), as schema_error() means to do. */
static void defect_schema_value_rule(void)
{
    static const struct {
        const char *from, *to, *rule;
    } cases[] = {
        {"Name=\"Q_OUT\" MaxMessageSize=\"8\"", "Name=\"Q_OUT\" MaxMessageSize=\"12x\"",
         "numbers are positive integers"},
        {"WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"",
         "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"abc\"", "durations are decimal seconds"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *text = replace_once(base_xml, cases[i].from, cases[i].to);
        const char *path = text ? write_module("bad.xml", text) : NULL;
        free(text);
        REQUIRE(path);
        ske_module_cfg_t *m = NULL;
        ske_diag_t d;
        CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_E_CONFIG);
        CHECK_STR(d.rule, cases[i].rule);
        ske_config_free(m);
    }
}

/* Every diagnostic line states the rule, also when no element is named (parse errors). */
static void defect_diag_format_drops_rule(void)
{
    ske_diag_t d = {.file = "m.xml", .line = 3, .message = "bad", .rule = "well-formed XML"};
    char buf[256];
    ske_diag_format(&d, buf, sizeof buf);
    CHECK_CONTAINS(buf, "(rule: well-formed XML)");
}

/* WindowStartSeconds + WindowDurationSeconds past INT64_MAX ns wraps negative and slips
 * through "windows end within the major frame" (signed overflow: undefined behaviour). */
static void defect_window_end_overflow(void)
{
    char *t1 = replace_once(base_xml, "WindowStartSeconds=\"0.01\" WindowDurationSeconds=\"0.01\"",
                            "WindowStartSeconds=\"9000000000\" WindowDurationSeconds=\"9000000000\"");
    const char *path = t1 ? write_module("bad.xml", t1) : NULL;
    free(t1);
    REQUIRE(path);
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    CHECK_EQ(ske_config_load(path, &no_resolve, &m, &d), SKE_E_CONFIG);
    CHECK_STR(d.rule, "windows end within the major frame");
    ske_config_free(m);
}

/* strtoull skips leading white space and accepts a sign after it: "\t-1" is read as
 * 2^64 - 1 although " 1" and "-1" are refused. */
static void defect_parse_u64_leading_space(void)
{
    uint64_t v = 0;
    CHECK(!ske_parse_u64("\t-1", &v));
    CHECK(!ske_parse_u64("\n5", &v));
}

static void remove_tmp_dir(void)
{
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmp_dir);
}

int main(int argc, char **argv)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    atexit(remove_tmp_dir);
    RUN(defect_line_of_multiline_start_tag);
    RUN(defect_schema_value_rule);
    RUN(defect_diag_format_drops_rule);
    RUN(defect_window_end_overflow);
    RUN(defect_parse_u64_leading_space);
    RUN(test_parse_seconds);
    RUN(test_parse_u64);
    RUN(test_load_example);
    RUN(test_load_schedule_and_extension);
    RUN(test_resolve_executables);
    RUN(test_base_module_is_valid);
    RUN(test_invalid_modules);
    RUN(test_limits);
    RUN(test_unreadable_inputs);
    RUN(test_diag_format);
    RUN(test_diag_set);
    return ske_test_result();
}
