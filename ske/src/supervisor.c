/* SPDX-License-Identifier: Apache-2.0 */
/* The SKE's supervisor: creates the emulator (port memory, control blocks, trace), runs the
 * cyclic plan window after window (in lockstep with the CAN bus when asked), and destroys it.
 * The rest is in spawn.c, portmem.c, window.c, hm_actions.c, modes.c and stats_out.c. */
#include "ske__supervisor.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <unistd.h>

#define SAMPLE_LIMIT 2000000
#define SYSTEM_MESSAGE_MAX (1u << 20) /* the largest MaxMessageSize the schema accepts */

void ske_request_stop(ske_t *ske, int signo) { ske->stop_signal = signo; }
void ske_notify_child(ske_t *ske) { ske->child_event = 1; }
int ske_stop_signal(const ske_t *ske) { return ske->stop_signal; }
bool ske_shut_down_by_hm(const ske_t *ske) { return ske->hm_shutdown; }

/* ---- life cycle ----------------------------------------------------------------------- */

int ske_check_options(const ske_module_cfg_t *cfg, const ske_run_opts_t *opts, char *err,
                      size_t errlen)
{
    ske_faults_t *fs = malloc(sizeof *fs);
    ske_switches_t sw;
    if (!fs) {
        snprintf(err, errlen, "out of memory");
        return SKE_E_NOMEM;
    }
    int rc = ske__faults_parse(fs, cfg, opts->faults, opts->n_faults, err, errlen);
    if (rc == SKE_OK)
        rc = ske__switches_parse(&sw, cfg, opts->test_switches, opts->n_test_switches, err, errlen);
    free(fs);
    return rc;
}

int ske_create(const ske_module_cfg_t *cfg, const ske_run_opts_t *opts, ske_t **out, char *err,
               size_t errlen)
{
    *out = NULL;
    ske_t *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return SKE_E_NOMEM;
    }
    s->cfg = cfg;
    s->opts = *opts;
    int rc = ske__faults_parse(&s->faults, cfg, opts->faults, opts->n_faults, err, errlen);
    if (rc == SKE_OK)
        rc = ske__switches_parse(&s->sw, cfg, opts->test_switches, opts->n_test_switches, err, errlen);
    if (rc != SKE_OK) {
        free(s);
        return rc;
    }
    s->cur_partition = -1;
    s->next_schedule = cfg->n_schedules ? cfg->initial_schedule : 0;
    s->time_mode = opts->time_mode >= 0 ? (ske_time_mode_t)opts->time_mode : cfg->time_mode;
    snprintf(s->node, sizeof s->node, "%s", opts->node ? opts->node : cfg->node);
    s->xfer = malloc(SYSTEM_MESSAGE_MAX);
    if (!s->xfer) {
        free(s);
        snprintf(err, errlen, "out of memory");
        return SKE_E_NOMEM;
    }
    ske_samples_init(&s->switch_ns, SAMPLE_LIMIT);
    ske_samples_init(&s->jitter_ns, SAMPLE_LIMIT);
    snprintf(s->exit_reason, sizeof s->exit_reason, "frames");
    for (int i = 0; i < cfg->n_partitions; i++) {
        ske_part_t *p = &s->parts[i];
        p->cfg = &cfg->partitions[i];
        p->index = i;
        p->state = SKE_PS_NOT_STARTED;
        p->ctl_fd = -1;
        p->output_fd = -1;
        p->output_limit = -1;
        p->start_condition = 0; /* NORMAL_START */
        p->initial_mode = SKE_MODE_COLD_START;
        for (int k = 0; k < SKE_MAX_PORTS; k++)
            p->ports[k].fd = p->ports[k].fd_ro = -1;
    }
    rc = ske__setup_ports(s, err, errlen);
    if (rc == SKE_OK)
        rc = ske__open_outputs(s, err, errlen);
    if (rc != SKE_OK)
        goto fail;
    for (int i = 0; i < cfg->n_partitions; i++) {
        ske_part_t *p = &s->parts[i];
        char name[64];
        snprintf(name, sizeof name, "ima-ctl-%s", p->cfg->name);
        void *mem;
        p->ctl_fd = ske__memobj(name, sizeof(ske_ctl_t), &mem);
        if (p->ctl_fd < 0) {
            snprintf(err, errlen, "control block: %s", strerror(-p->ctl_fd));
            rc = SKE_E_SYS;
            goto fail;
        }
        p->ctl = mem;
    }
    if (ske_trace_open(&s->trace, opts->trace_path, s->node) != 0) {
        snprintf(err, errlen, "cannot write the trace %s: %s", opts->trace_path, strerror(errno));
        rc = SKE_E_IO;
        goto fail;
    }
    *out = s;
    return SKE_OK;
fail:
    ske_destroy(s);
    return rc;
}

/* Lockstep: a window starting at t runs only once the bus has granted time past t; until then
 * the node reports its quantum done and waits (nodes/include/canbus/proto.h). Its DONE says
 * that nothing is to be done before t: the bus does not grant the quanta in between. */
static int wait_for_quantum(ske_t *s, int64_t t, char *err, size_t errlen)
{
    while (t >= s->bus.granted_ns) {
        int r = canbus_client_done_wait_for(&s->bus, t);
        if (r == CANBUS_STOPPED) {
            s->bus_stopped = true;
            return SKE_OK;
        }
        if (r == -EINTR) {
            if (s->stop_signal)
                return SKE_OK;
            if (s->child_event)
                ske__reap(s);
            continue;
        }
        if (r < 0) {
            snprintf(err, errlen, "CAN bus: %s", strerror(-r));
            return SKE_E_IO;
        }
    }
    return SKE_OK;
}

/* In lockstep, a window of a partition that is not a system partition runs as soon as the
 * windows before it have run, without waiting for the bus to grant its start: the sandbox
 * lets only system partitions open files and sockets (SKE_SANDBOX_IO), so such a window can
 * touch nothing outside the node but its ports and its output file, all read in emulated
 * time, and runs the same whenever the host runs it. The node is then woken only for its
 * system partitions' windows. Not on a bus paced by the wall clock, nor past the run's end. */
static bool runs_ahead(const ske_t *s, const ske_slot_t *slot)
{
    const ske_partition_cfg_t *cfg = s->parts[slot->window->partition].cfg;
    return !cfg->system_partition && s->time_mode != SKE_TIME_REALTIME &&
           !(s->bus.flags & CANBUS_WELCOME_REALTIME) && !s->sw.every_quantum &&
           (s->bus.end_ns < 0 || slot->start_ns < s->bus.end_ns);
}

int ske_run(ske_t *s, char *err, size_t errlen)
{
    const ske_module_cfg_t *m = s->cfg;
    int rc = SKE_OK;
    s->start_mono_ns = ske_mono_ns();
    s->pid = getpid();
    /* Partitions run as the same user: without this, /proc/<ske>/fd would hand them every
     * other partition's memory. */
    prctl(PR_SET_DUMPABLE, 0UL);
    if (s->time_mode == SKE_TIME_REALTIME)
        prctl(PR_SET_TIMERSLACK, 1UL); /* the default 50 µs slack would be window jitter */
    s->epoch_mono_ns = s->start_mono_ns; /* refined below for real-time mode */
    if (s->opts.lockstep_path) {
        char berr[256];
        int brc = canbus_client_connect(&s->bus, s->opts.lockstep_path, s->node,
                                        CANBUS_ROLE_LOCKSTEP, s->opts.node_index, berr, sizeof berr);
        if (brc != CANBUS_OK) {
            snprintf(err, errlen, "%s", berr);
            snprintf(s->exit_reason, sizeof s->exit_reason, "error");
            rc = SKE_E_IO;
            goto done;
        }
        s->on_bus = true;
    }
    for (int i = 0; i < m->n_partitions && rc == SKE_OK; i++)
        rc = ske__spawn(s, &s->parts[i], err, errlen);
    if (rc != SKE_OK) {
        snprintf(s->exit_reason, sizeof s->exit_reason, s->stop_signal ? "signal" : "error");
        goto done;
    }
    /* Module time 0 is now (plus a little margin in real time so the first window starts
     * on time); partitions read the epoch from their control block at each grant. */
    s->epoch_mono_ns = ske_mono_ns() + (s->time_mode == SKE_TIME_REALTIME ? 2000000 : 0);
    for (int i = 0; i < m->n_partitions; i++)
        s->parts[i].ctl->epoch_mono_ns = s->epoch_mono_ns;
    ske__trace_module_start(s);
    ske_slot_t slot;
    for (ske_plan_first(m, &slot); s->opts.frames < 0 || slot.frame < s->opts.frames;
         ske_plan_next(m, &slot)) {
        if (s->stop_signal || s->hm_shutdown)
            break;
        if (slot.index == 0 && slot.frame > INT64_MAX / m->major_frame_ns - 1) {
            /* The next major frame would start past the end of the 64-bit nanosecond clock
             * (about 292 years of module time). */
            snprintf(s->exit_reason, sizeof s->exit_reason, "end_of_time");
            break;
        }
        if (s->on_bus && !runs_ahead(s, &slot) &&
            (rc = wait_for_quantum(s, slot.start_ns, err, errlen)) != SKE_OK)
            break;
        if (s->bus_stopped || s->stop_signal)
            break;
        if (slot.index == 0 && m->n_schedules && s->next_schedule != slot.schedule)
            ske__switch_schedule(s, &slot, s->next_schedule);
        if (slot.index == 0)
            ske__faults_frame_start(s, slot.start_ns, slot.frame);
        if (slot.index == 0 && s->hm_reset) {
            rc = ske__hm_module_reset(s, slot.start_ns, err, errlen);
            if (rc != SKE_OK)
                break;
        }
        rc = ske__run_window(s, &slot, err, errlen);
        if (rc != SKE_OK)
            break;
        if (slot.index == m->n_windows - 1) {
            s->frames_done = slot.frame + 1;
            ske_trace_maybe_flush(&s->trace, ske_mono_ns());
        }
    }
    if (rc != SKE_OK)
        snprintf(s->exit_reason, sizeof s->exit_reason, "error");
    else if (s->stop_signal)
        snprintf(s->exit_reason, sizeof s->exit_reason, "signal");
    else if (s->hm_shutdown)
        snprintf(s->exit_reason, sizeof s->exit_reason, "hm_shutdown");
    else if (s->bus_stopped)
        snprintf(s->exit_reason, sizeof s->exit_reason, "bus_stop");
done:
    if (s->on_bus)
        canbus_client_close(&s->bus);
    for (int i = 0; i < m->n_partitions; i++)
        ske__kill_partition(&s->parts[i]);
    /* A shutdown mid-frame stops at the end of the window where it was decided. */
    int64_t stop_t = s->frames_done * m->major_frame_ns;
    if (s->hm_shutdown && s->win_end_ns > stop_t)
        stop_t = s->win_end_ns;
    ske_trace_begin(&s->trace, stop_t, "ske", "module_stop");
    ske_trace_int(&s->trace, "frames", s->frames_done);
    ske_trace_str(&s->trace, "reason", s->exit_reason);
    ske_trace_end(&s->trace);
    int trc = ske_trace_close(&s->trace);
    int src = ske__write_stats(s, (double)(ske_mono_ns() - s->start_mono_ns) / 1e9);
    /* Recorded data that could not be written is a failed run, whatever else went right. */
    if (trc != 0 && rc == SKE_OK) {
        snprintf(err, errlen, "the trace %s could not be written: %s", s->opts.trace_path,
                 strerror(-trc));
        rc = SKE_E_IO;
    }
    if (src != 0 && rc == SKE_OK) {
        snprintf(err, errlen, "the statistics %s could not be written: %s", s->opts.stats_path,
                 strerror(-src));
        rc = SKE_E_IO;
    }
    return rc;
}

void ske_destroy(ske_t *s)
{
    if (!s)
        return;
    for (int i = 0; i < SKE_MAX_PARTITIONS; i++) {
        ske_part_t *p = &s->parts[i];
        if (!p->cfg)
            continue;
        ske__kill_partition(p);
        ske__free_ports(p);
        if (p->ctl)
            munmap(p->ctl, sizeof(ske_ctl_t));
        if (p->ctl_fd >= 0)
            close(p->ctl_fd);
    }
    ske__close_outputs(s);
    ske_trace_close(&s->trace);
    ske_samples_free(&s->switch_ns);
    ske_samples_free(&s->jitter_ns);
    free(s->xfer);
    free(s);
}
