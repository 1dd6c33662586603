/* SPDX-License-Identifier: Apache-2.0 */
/* What the SKE writes about the module as a whole: the module_start event (the plan's
 * windows) and, at the end, the statistics file. */
#include "ske__supervisor.h"

#include <errno.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

/* The module's windows as a JSON array: the trace's module_start and the statistics. */
static void write_windows_json(FILE *f, const ske_module_cfg_t *m)
{
    fputc('[', f);
    for (int i = 0; i < m->n_windows; i++) {
        const ske_window_cfg_t *w = &m->windows[i];
        fprintf(f, "%s{\"window\":%d,\"partition\":", i ? "," : "", w->id);
        ske_json_escape(f, m->partitions[w->partition].name, strlen(m->partitions[w->partition].name));
        fprintf(f, ",\"offset_ns\":%" PRId64 ",\"duration_ns\":%" PRId64, w->offset_ns,
                w->duration_ns);
        if (m->n_schedules > 1)
            fprintf(f, ",\"schedule\":%d", m->schedules[w->schedule].id);
        fputc('}', f);
    }
    fputc(']', f);
}

void ske__trace_module_start(ske_t *s)
{
    const ske_module_cfg_t *m = s->cfg;
    ske_trace_begin(&s->trace, 0, "ske", "module_start");
    ske_trace_str(&s->trace, "module", m->module_name);
    ske_trace_str(&s->trace, "time_mode", s->time_mode == SKE_TIME_REALTIME ? "realtime" : "emulated");
    ske_trace_int(&s->trace, "major_frame_ns", m->major_frame_ns);
    if (s->trace.f) {
        fputs(",\"windows\":", s->trace.f);
        write_windows_json(s->trace.f, m);
        if (m->n_schedules > 1)
            fprintf(s->trace.f, ",\"initial_schedule\":%d", m->schedules[m->initial_schedule].id);
    }
    ske_trace_end(&s->trace);
    ske__switches_trace(s);
    for (int i = 0; i < m->n_partitions; i++)
        ske__trace_mode(s, &s->parts[i], 0, SKE_MODE_COLD_START, SKE_MODE_IDLE, "power-on");
}

int ske__write_stats(ske_t *s, double wall_s)
{
    if (!s->opts.stats_path)
        return 0;
    FILE *f = fopen(s->opts.stats_path, "w");
    if (!f)
        return -errno;
    const ske_module_cfg_t *m = s->cfg;
    fputs("{\"module\":", f);
    ske_json_escape(f, m->module_name, strlen(m->module_name));
    fputs(",\"node\":", f);
    ske_json_escape(f, s->node, strlen(s->node));
    fprintf(f, ",\"mode\":\"%s\",\"major_frame_ns\":%" PRId64 ",\"frames\":%" PRId64
               ",\"emulated_ns\":%" PRId64 ",\"wall_s\":%.6f,\"exit_reason\":\"%s\",\"partitions\":[",
            s->time_mode == SKE_TIME_REALTIME ? "realtime" : "emulated", m->major_frame_ns,
            s->frames_done, s->frames_done * m->major_frame_ns, wall_s, s->exit_reason);
    for (int i = 0; i < m->n_partitions; i++) {
        const ske_part_t *p = &s->parts[i];
        int64_t per_frame = ske_plan_partition_ns(m, i);
        int nwin = p->cfg->n_windows;
        fprintf(f, "%s{\"id\":%d,\"name\":", i ? "," : "", p->cfg->id);
        ske_json_escape(f, p->cfg->name, strlen(p->cfg->name));
        fprintf(f, ",\"windows_per_frame\":%d,\"window_ns_per_frame\":%" PRId64
                   ",\"windows\":%llu,\"cpu_ns\":%" PRId64 ",\"overruns\":%llu,\"restarts\":%llu"
                   ",\"state\":\"%s\",\"exit_status\":",
                nwin, per_frame, (unsigned long long)p->windows, p->cpu_ns,
                (unsigned long long)p->overruns, (unsigned long long)p->restarts,
                ske__pstate_name(p->state));
        /* From how the process ended, not from the state: a partition idled after it ended
         * still ended that way, and a failed restart is no crash of a process. */
        if (p->ended)
            fprintf(f, "%d", p->exit_code);
        else
            fputs("null", f);
        const char *sig = p->ended && p->ended_by_signal ? sigabbrev_np(p->exit_code) : NULL;
        fputs(",\"exit_signal\":", f);
        if (sig)
            fprintf(f, "\"%s\"", sig);
        else
            fputs("null", f);
        fprintf(f, ",\"cpu_outside_windows_ns_max\":%" PRId64, p->cpu_outside_max_ns);
        if (p->cfg->hm_log_port >= 0) /* HM decisions its full HM log port could not take */
            fprintf(f, ",\"hm_log_lost\":%llu", (unsigned long long)p->hm_log_lost);
        fputc('}', f);
    }
    fprintf(f, "],\"hm_events\":%llu", (unsigned long long)s->hm_events);
    fputs(",\"windows\":", f);
    write_windows_json(f, m);
    fputs(",\"window_switch_us\":", f);
    ske_samples_json_us(&s->switch_ns, f);
    fputs(",\"jitter_us\":", f);
    ske_samples_json_us(&s->jitter_ns, f);
    fputs(",\"channels\":[", f);
    for (int c = 0; c < m->n_channels; c++) {
        const ske_channel_cfg_t *ch = &m->channels[c];
        uint64_t msgs = s->chan_messages[c];
        if (ch->kind == SKE_PORT_SAMPLING) {
            const ske_sampling_hdr_t *h = s->parts[ch->src.partition].ports[ch->src.port].mem;
            msgs = atomic_load(&h->seq);
        }
        fprintf(f, "%s{\"id\":%d,\"name\":", c ? "," : "", ch->id);
        ske_json_escape(f, ch->name, strlen(ch->name));
        fprintf(f, ",\"kind\":\"%s\",\"messages\":%llu,\"overflows\":%llu}",
                ch->kind == SKE_PORT_SAMPLING ? "sampling" : "queuing", (unsigned long long)msgs,
                (unsigned long long)s->chan_overflows[c]);
    }
    fputs("]}\n", f);
    int rc = ferror(f) ? -EIO : 0;
    if (fclose(f) != 0 && rc == 0)
        rc = -(errno ? errno : EIO);
    return rc;
}
