/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of creating an emulator (ske_create) and of reading a partition's event ring
 * (ske__drain_events): what stops the SKE before a partition starts, and what the trace gets
 * from events the partition wrote, field by field. No partition process is started. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ske/config.h"
#include "ske__supervisor.h"
#include "ske_test.h"

#define EXAMPLE IMA_SOURCE_DIR "/config/examples/three_partitions.xml"

static char tmp_dir[] = "/tmp/ske_test_create.XXXXXX";

static ske_module_cfg_t *load(const char *path)
{
    ske_load_opts_t opts = {.schema_dir = IMA_SOURCE_DIR "/config/schema",
                            .resolve_executables = false};
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    return ske_config_load(path, &opts, &m, &d) == SKE_OK ? m : NULL;
}

/* The example module with the monitor writing an output file. */
static ske_module_cfg_t *load_with_output_file(void)
{
    FILE *in = fopen(EXAMPLE, "r");
    if (!in)
        return NULL;
    static char text[1 << 16];
    size_t n = fread(text, 1, sizeof text - 1, in);
    fclose(in);
    text[n] = '\0';
    const char *from = "<ima:Linux Executable=\"ex_monitor\"/>";
    char *at = strstr(text, from);
    if (!at)
        return NULL;
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/with_output.xml", tmp_dir);
    FILE *out = fopen(path, "w");
    if (!out)
        return NULL;
    fprintf(out, "%.*s<ima:Linux Executable=\"ex_monitor\" OutputFile=\"monitor.log\"/>%s",
            (int)(at - text), text, at + strlen(from));
    fclose(out);
    return load(path);
}

/* ske_create of m with its trace at tmp_dir/name (the path left in trace). */
static int create_tracing(const ske_module_cfg_t *m, const char *name, char trace[PATH_MAX],
                          ske_t **s, char *err, size_t errlen)
{
    snprintf(trace, PATH_MAX, "%s/%s", tmp_dir, name);
    ske_run_opts_t o = {.frames = 1, .time_mode = -1, .trace_path = trace};
    return ske_create(m, &o, s, err, errlen);
}

static void test_options_that_cannot_apply(void)
{
    ske_module_cfg_t *m = load(EXAMPLE);
    REQUIRE(m != NULL);
    char err[512] = "";
    ske_t *s = (ske_t *)1;
    const char *fault[] = {"stuck_output:fid=s,at=1s,partition=nobody,port=SP_STATE"};
    ske_run_opts_t o = {.frames = 1, .time_mode = -1, .faults = fault, .n_faults = 1};
    CHECK_EQ(ske_check_options(m, &o, err, sizeof err), SKE_E_CONFIG);
    CHECK_CONTAINS(err, "nobody");
    err[0] = '\0';
    CHECK_EQ(ske_create(m, &o, &s, err, sizeof err), SKE_E_CONFIG);
    CHECK(s == NULL);
    CHECK_CONTAINS(err, "nobody");
    const char *sw[] = {"no-such-switch"};
    ske_run_opts_t o2 = {.frames = 1, .time_mode = -1, .test_switches = sw, .n_test_switches = 1};
    err[0] = '\0';
    CHECK_EQ(ske_create(m, &o2, &s, err, sizeof err), SKE_E_CONFIG);
    CHECK(s == NULL);
    CHECK_CONTAINS(err, "no-such-switch");
    ske_config_free(m);
}

static void test_files_it_cannot_write(void)
{
    ske_module_cfg_t *m = load(EXAMPLE);
    REQUIRE(m != NULL);
    char err[512] = "", trace[PATH_MAX];
    ske_t *s = (ske_t *)1;
    CHECK_EQ(create_tracing(m, "missing/trace.jsonl", trace, &s, err, sizeof err), SKE_E_IO);
    CHECK(s == NULL);
    CHECK_CONTAINS(err, "cannot write the trace");
    CHECK_CONTAINS(err, trace);
    ske_config_free(m);

    m = load_with_output_file();
    REQUIRE(m != NULL);
    char outdir[PATH_MAX];
    snprintf(outdir, sizeof outdir, "%s/missing", tmp_dir);
    ske_run_opts_t o2 = {.frames = 1, .time_mode = -1, .output_dir = outdir};
    err[0] = '\0';
    CHECK(ske_create(m, &o2, &s, err, sizeof err) != SKE_OK);
    CHECK(s == NULL);
    CHECK_CONTAINS(err, "partition 'monitor': cannot open its output file");
    /* Where it can: created, and nothing started until ske_run. */
    o2.output_dir = tmp_dir;
    CHECK_EQ(ske_create(m, &o2, &s, err, sizeof err), SKE_OK);
    if (s) {
        CHECK_EQ(s->parts[2].state, SKE_PS_NOT_STARTED);
        CHECK(s->parts[2].output_fd >= 0);
    }
    ske_destroy(s);
    ske_destroy(NULL);
    ske_config_free(m);
}

/* ---- the event ring --------------------------------------------------------------------- */

static void put(ske_ctl_t *c, int64_t t, uint32_t kind, int32_t a, int32_t b, const char *text,
                uint32_t len)
{
    uint32_t head = atomic_load(&c->ev_head);
    ske_event_t *e = &c->ev[head % SKE_EVENT_RING];
    *e = (ske_event_t){.t_ns = t, .kind = kind, .a = a, .b = b, .len = len};
    memcpy(e->text, text, strlen(text) < SKE_EVENT_TEXT ? strlen(text) : SKE_EVENT_TEXT);
    atomic_store(&c->ev_head, head + 1);
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    char *buf = calloc(1, 1 << 16);
    if (buf && fread(buf, 1, (1 << 16) - 1, f) == 0)
        buf[0] = '\0';
    fclose(f);
    return buf;
}

static void test_drain_events(void)
{
    ske_module_cfg_t *m = load(EXAMPLE);
    REQUIRE(m != NULL);
    char err[512] = "", trace[PATH_MAX];
    ske_t *s = NULL;
    CHECK_EQ(create_tracing(m, "events.jsonl", trace, &s, err, sizeof err), SKE_OK);
    REQUIRE(s != NULL);
    ske_part_t *p = &s->parts[0]; /* producer: ports SP_STATE, QP_CMD */
    ske_ctl_t *c = p->ctl;
    put(c, 1000, SKE_EV_MODE, SKE_MODE_NORMAL, SKE_MODE_COLD_START, "", 0);
    put(c, 1000, SKE_EV_MODE, 4, SKE_MODE_COLD_START, "", 0); /* no such mode */
    put(c, 1000, SKE_EV_MODE, SKE_MODE_NORMAL, -1, "", 0);
    put(c, 2000, SKE_EV_PORT_VALIDITY, 1, 1, "", 0);
    put(c, 2000, SKE_EV_PORT_VALIDITY, 0, 0, "", 0);
    put(c, 2000, SKE_EV_PORT_VALIDITY, 2, 1, "", 0); /* it has two ports */
    put(c, 3000, SKE_EV_PROCESS, 1, SKE_PROC_EV_START, "produce", 7);
    put(c, 3000, SKE_EV_PROCESS, 1, SKE_PROC_EV_STOP, "produce", 7);
    put(c, 4000, SKE_EV_HM, 99, 1, "", SKE_EVENT_TEXT); /* no such error */
    put(c, 5000, 77, 0, 0, "", 0); /* no such kind */
    put(c, -5, SKE_EV_APP_MESSAGE, 0, 0, "before", 6); /* before its window */
    put(c, 6000, SKE_EV_APP_MESSAGE, 2, 0, "fits", 4);
    atomic_store(&c->ev_dropped, 2);
    ske__drain_events(s, p, 0, 10000);
    CHECK_EQ(atomic_load(&c->ev_tail), atomic_load(&c->ev_head));
    CHECK_EQ(atomic_load(&c->ev_dropped), 0);
    /* A ring claiming more than it holds: nothing of it is read. */
    put(c, 7000, SKE_EV_APP_MESSAGE, 0, 0, "lost", 4);
    atomic_fetch_add(&c->ev_head, SKE_EVENT_RING);
    ske__drain_events(s, p, 0, 10000);
    CHECK_EQ(atomic_load(&c->ev_tail), atomic_load(&c->ev_head));
    ske_destroy(s);
    char *text = read_all(trace);
    REQUIRE(text != NULL);
    CHECK_CONTAINS(text, "\"t_ns\":1000,\"node\":\"node1\",\"src\":\"producer\",\"kind\":\"mode\","
                         "\"partition\":\"producer\",\"mode\":\"NORMAL\",\"from\":\"COLD_START\"}");
    CHECK_CONTAINS(text, "\"kind\":\"port\",\"event\":\"valid\",\"partition\":\"producer\","
                         "\"port\":\"QP_CMD\"}");
    CHECK_CONTAINS(text, "\"event\":\"invalid\",\"partition\":\"producer\",\"port\":\"SP_STATE\"}");
    CHECK_CONTAINS(text, "\"kind\":\"process\",\"process\":1,\"name\":\"produce\",\"event\":\"start\"}");
    CHECK_CONTAINS(text, "\"name\":\"produce\",\"event\":\"stop\"}");
    CHECK_CONTAINS(text, "\"t_ns\":0,\"node\":\"node1\",\"src\":\"producer\",\"kind\":\"app_message\","
                         "\"process\":0,\"text\":\"before\",\"suspect_time\":true,"
                         "\"reported_t_ns\":-5}");
    CHECK_CONTAINS(text, "\"process\":2,\"text\":\"fits\"}");
    CHECK_CONTAINS(text, "\"t_ns\":10000,\"node\":\"node1\",\"src\":\"ske\",\"kind\":\"events_dropped\","
                         "\"partition\":\"producer\",\"count\":2}");
    /* One mode, two port events, two process events, two messages, one count: nothing of the
     * events that make no sense, nor of the impossible ring. */
    int lines = 0;
    for (const char *q = text; (q = strchr(q, '\n')); q++)
        lines++;
    CHECK_EQ(lines, 8);
    CHECK(strstr(text, "lost") == NULL);
    free(text);
    ske_config_free(m);
}

static void remove_tmp_dir(void)
{
    static const char *const files[] = {"with_output.xml", "monitor.log", "events.jsonl"};
    char path[PATH_MAX];
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", tmp_dir, files[i]);
        unlink(path);
    }
    rmdir(tmp_dir);
}

int main(void)
{
    if (!mkdtemp(tmp_dir))
        return 1;
    RUN(test_options_that_cannot_apply);
    RUN(test_files_it_cannot_write);
    RUN(test_drain_events);
    remove_tmp_dir();
    return ske_test_result();
}
