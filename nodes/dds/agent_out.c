/* SPDX-License-Identifier: Apache-2.0 */
/* The DDS agent's trace (JSON lines), statistics (one JSON object at exit) and log lines. */
#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "agent__agent.h"
#include "agent__cipher.h"
#include "agent__hmac.h"

int64_t agent_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

int64_t agent_wall_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

void agent_log(agent_t *a, const char *fmt, ...)
{
    if (a->o.quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "ima-dds-node %s: ", a->node_name);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* The trace has no emulated clock of its own: t_ns is the emulated time of the latest
 * request from io (0 before the first), t_wall_ns the wall clock of the event. */
bool agent_trace_begin_at(agent_t *a, const char *kind, int64_t t_ns)
{
    if (!a->trace)
        return false;
    fprintf(a->trace,
            "{\"t_wall_ns\":%" PRId64 ",\"t_ns\":%" PRId64
            ",\"node\":\"%s\",\"src\":\"dds\",\"kind\":\"%s\"",
            agent_wall_ns(), t_ns, a->node_name, kind);
    return true;
}

bool agent_trace_begin(agent_t *a, const char *kind)
{
    return agent_trace_begin_at(a, kind, a->last_t_ns);
}

void agent_trace_end(agent_t *a)
{
    fputs("}\n", a->trace);
    /* Events are rare: flushing each keeps the trace complete if the agent is killed. */
    fflush(a->trace);
}

void agent_trace_simple(agent_t *a, const char *kind)
{
    if (agent_trace_begin(a, kind))
        agent_trace_end(a);
}

void agent_trace_nodes(agent_t *a, const char *key, uint32_t mask)
{
    fprintf(a->trace, ",\"%s\":[", key);
    bool first = true;
    for (unsigned k = 1; k <= 32; k++)
        if (mask & (1u << (k - 1))) {
            fprintf(a->trace, "%s\"node%u\"", first ? "" : ",", k);
            first = false;
        }
    fputc(']', a->trace);
}

int agent_lat_init(agent_lat_t *l)
{
    l->n = 0;
    l->ns = malloc(AGENT_LAT_MAX * sizeof *l->ns);
    return l->ns ? 0 : -1;
}

void agent_lat_add(agent_lat_t *l, int64_t ns)
{
    if (!l->ns || l->n >= AGENT_LAT_MAX)
        return;
    if (ns < 0)
        ns = 0;
    l->ns[l->n++] = ns > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)ns;
}

void agent_lat_free(agent_lat_t *l)
{
    free(l->ns);
    l->ns = NULL;
    l->n = 0;
}

static int cmp_u32(const void *x, const void *y)
{
    uint32_t p = *(const uint32_t *)x, q = *(const uint32_t *)y;
    return p < q ? -1 : p > q;
}

static double pct_us(const uint32_t *sorted, uint32_t n, double p)
{
    /* nearest-rank percentile */
    uint32_t i = (uint32_t)(p * n / 100.0 + 0.999999);
    if (i < 1)
        i = 1;
    if (i > n)
        i = n;
    return sorted[i - 1] / 1000.0;
}

/* "key":{"count":N,"min":..,"median":..,"p95":..,"max":..} in microseconds */
static void write_lat(FILE *f, const char *key, const agent_lat_t *l)
{
    fprintf(f, "\"%s\":", key);
    uint32_t *sorted = l->n ? malloc(l->n * sizeof *sorted) : NULL;
    if (!sorted) {
        fputs("{\"count\":0,\"min\":null,\"median\":null,\"p95\":null,\"max\":null}", f);
        return;
    }
    memcpy(sorted, l->ns, l->n * sizeof *sorted);
    qsort(sorted, l->n, sizeof *sorted, cmp_u32);
    fprintf(f, "{\"count\":%u,\"min\":%.1f,\"median\":%.1f,\"p95\":%.1f,\"max\":%.1f}", l->n,
            sorted[0] / 1000.0, pct_us(sorted, l->n, 50), pct_us(sorted, l->n, 95),
            sorted[l->n - 1] / 1000.0);
    free(sorted);
}

/* A JSON string literal: the refused list's texts hold process names, which may hold anything. */
static void write_json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20 || c >= 0x7F)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void write_guid(FILE *f, const dds_guid_t *g)
{
    for (size_t b = 0; b < sizeof g->v; b++)
        fprintf(f, "%02x%s", g->v[b], b % 4 == 3 && b < 15 ? ":" : "");
}

/* The writers whose samples were refused (agent_dds.c from_node): which partition they
 * write in, the node they claimed, how many, and their participant. */
static void write_refused(const agent_t *a, FILE *f)
{
    uint64_t reused, derived, prefetched, as_given;
    agent_hmac_counts(&reused, &derived);
    agent_cipher_counts(&prefetched, &as_given);
    fprintf(f,
            "\"security\":%s,\"session_keys\":{\"reused\":%" PRIu64 ",\"derived\":%" PRIu64
            "},\"cipher_inits\":{\"prefetched\":%" PRIu64 ",\"as_given\":%" PRIu64
            "},\"refused_samples\":%" PRIu64 ",\"refused\":[",
            a->o.security_dir ? "true" : "false", reused, derived, prefetched, as_given,
            a->refused_samples);
    bool first = true;
    for (int i = 0; i < a->n_writers; i++) {
        const agent_writer_t *w = &a->writers[i];
        if (!w->refused)
            continue;
        fprintf(f, "%s{\"topic\":\"%s\",\"partition\":\"%s\",\"claimed_node\":%u,"
                   "\"samples\":%" PRIu64 ",\"participant\":\"",
                first ? "" : ",", agent_topic_name[w->topic], w->partition, w->claimed, w->refused);
        write_guid(f, &w->participant);
        fputs("\"}", f);
        first = false;
    }
    fputs("],\"foreign_participants\":[", f);
    for (int i = 0; i < a->n_foreign; i++) {
        const agent_foreign_t *p = &a->foreign[i];
        fprintf(f, "%s{\"guid\":\"", i ? "," : "");
        write_guid(f, &p->guid);
        fprintf(f, "\",\"process\":\"%s\",\"pid\":%ld,\"refused\":%s}", p->process, p->pid,
                p->refused ? "true" : "false");
    }
    fputs("],", f);
}

int agent_write_stats(agent_t *a)
{
    if (!a->o.stats_path)
        return 0;
    FILE *f = fopen(a->o.stats_path, "w");
    if (!f) {
        fprintf(stderr, "ima-dds-node %s: cannot write statistics to %s: %s\n", a->node_name,
                a->o.stats_path, strerror(errno));
        return -1;
    }
    fprintf(f, "{\"node\":%u,\"nodes\":%u,\"domain\":%u,\"mode\":\"%s\",\"wall_s\":%.3f,",
            a->o.node, a->o.nodes, a->o.domain, a->o.realtime ? "realtime" : "emulated",
            (agent_mono_ns() - a->start_mono_ns) / 1e9);
    fputs("\"topics\":{", f);
    for (int t = 0; t < T_COUNT; t++)
        fprintf(f,
                "%s\"%s\":{\"written\":%" PRIu64 ",\"read\":%" PRIu64 ",\"invalid\":%" PRIu64
                ",\"write_errors\":%" PRIu64 "}",
                t ? "," : "", agent_topic_name[t], a->ts[t].written, a->ts[t].read, a->ts[t].invalid,
                a->ts[t].write_errors);
    fprintf(f,
            "},\"agreed_frames\":%" PRIu64 ",\"partial\":%" PRIu64 ",\"waits\":%" PRIu64
            ",\"timeouts\":%" PRIu64 ",\"superseded\":%" PRIu64 ",\"stale\":%" PRIu64
            ",\"bad_datagrams\":%" PRIu64 ",\"io_connections\":%" PRIu64
            ",\"io_disconnects\":%" PRIu64 ",\"events_dropped\":%" PRIu64
            ",\"bound_sockets\":%u,",
            a->agreed, a->partial, a->waits, a->timeouts, a->superseded, a->agree.stale,
            a->bad_datagrams, a->io_connections, a->io_disconnects, a->ev_dropped,
            a->bound_sockets);
    fprintf(f, "\"withheld\":%" PRIu64 ",\"published_late\":%" PRIu64 ",\"lost_marks\":%" PRIu64
               ",\"deadline_paused\":%" PRIu64 ",\"deadline_covered\":%" PRIu64
               ",\"faults\":[",
            a->withheld, a->published_late, a->agree.lost, a->deadline_paused,
            a->deadline_covered);
    for (size_t i = 0; i < a->faults.n; i++)
        fprintf(f, "%s{\"fid\":\"%s\",\"class\":\"%s\",\"frames\":%" PRIu64 "}", i ? "," : "",
                a->faults.f[i].spec.fid, dds_fault_class(&a->faults.f[i]),
                a->faults.f[i].total_frames);
    fputs("],", f);
    write_refused(a, f);
    write_lat(f, "exchange_latency_us", &a->xch_lat);
    fputc(',', f);
    write_lat(f, "dds_latency_us", &a->dds_lat);
    fputs(",\"peers\":[", f);
    bool first = true;
    for (unsigned k = 1; k <= a->o.nodes; k++) {
        if (k == a->o.node)
            continue;
        const agent_peer_t *p = &a->peer[k - 1];
        fprintf(f,
                "%s{\"node\":%u,\"discovered\":%s,\"alive\":%s,\"dead\":%s,"
                "\"lost_wall_ns\":%" PRId64 ",\"deadline_misses\":%" PRIu64 "}",
                first ? "" : ",", k, p->discovered ? "true" : "false",
                p->alive ? "true" : "false", p->dead ? "true" : "false", p->lost_wall_ns,
                p->deadline_misses);
        first = false;
    }
    fprintf(f, "],\"io_refused\":%" PRIu64 ",\"refusals_unlisted\":%" PRIu64 ",\"refusals\":[",
            a->io_refused, a->refusals_unlisted);
    for (unsigned i = 0; i < a->n_refused; i++) {
        fprintf(f, "%s{\"what\":", i ? "," : "");
        write_json_str(f, a->refused[i].what);
        fputs(",\"detail\":", f);
        write_json_str(f, a->refused[i].detail);
        fputc('}', f);
    }
    fputs("]}\n", f);
    if (fclose(f) != 0) {
        fprintf(stderr, "ima-dds-node %s: cannot write statistics to %s: %s\n", a->node_name,
                a->o.stats_path, strerror(errno));
        return -1;
    }
    return 0;
}
