/* SPDX-License-Identifier: Apache-2.0 */
/* What the SKE hands partitions besides their ports: the output file it opens for a
 * partition that has no right to open one (ima:Linux OutputFile), and the module's
 * health-monitor log, each decision written into the queuing port a partition names
 * (ima:Linux HealthMonitorLogPort). */
#include "ske__supervisor.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

int ske__open_outputs(ske_t *s, char *err, size_t errlen)
{
    for (int i = 0; i < s->cfg->n_partitions; i++) {
        ske_part_t *p = &s->parts[i];
        p->output_fd = -1;
        const char *name = p->cfg->output_file;
        if (!name[0])
            continue;
        char path[2 * SKE_PATH_MAX + 2];
        if (name[0] == '/') {
            snprintf(path, sizeof path, "%s", name);
        } else {
            char dir[SKE_PATH_MAX];
            snprintf(dir, sizeof dir, "%s", s->cfg->path);
            snprintf(path, sizeof path, "%s/%s",
                     s->opts.output_dir ? s->opts.output_dir : dirname(dir), name);
        }
        /* Appended to: a partition restarted by its health monitor goes on after what its
         * last process wrote. Kept open by the SKE for the whole run. */
        p->output_fd = open(path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NOFOLLOW, 0644);
        if (p->output_fd < 0) {
            snprintf(err, errlen, "partition '%s': cannot open its output file %s: %s",
                     p->cfg->name, path, strerror(errno));
            return SKE_E_IO;
        }
    }
    return SKE_OK;
}

void ske__close_outputs(ske_t *s)
{
    for (int i = 0; i < SKE_MAX_PARTITIONS; i++) {
        ske_part_t *p = &s->parts[i];
        if (p->cfg && p->output_fd >= 0) {
            close(p->output_fd);
            p->output_fd = -1;
        }
    }
}

void ske__hm_log_publish(ske_t *s, int64_t t, const ske_part_t *about, hm_error_t err,
                         hm_level_t level, hm_action_t action, hm_state_t state, int32_t process,
                         const char *pname, const char *message, size_t mlen)
{
    ske_hm_log_t e;
    bool made = false;
    for (int i = 0; i < s->cfg->n_partitions; i++) {
        ske_part_t *q = &s->parts[i];
        int k = q->cfg->hm_log_port;
        if (k < 0 || !q->ports[k].mem || !q->ctl)
            continue;
        if (!made) {
            memset(&e, 0, sizeof e);
            e.t_ns = t;
            snprintf(e.partition, sizeof e.partition, "%s", about->cfg->name);
            if (pname)
                snprintf(e.process, sizeof e.process, "%s", pname);
            e.error = err;
            e.level = level;
            e.action = action;
            e.state = state;
            e.process_id = process;
            e.error_code = hm_apex_error_code(err);
            e.len = (uint32_t)(mlen < sizeof e.message ? mlen : sizeof e.message);
            if (message)
                memcpy(e.message, message, e.len);
            made = true;
        }
        const ske_port_cfg_t *pc = &q->cfg->ports[k];
        ske_port_desc_t *d = &q->ctl->ports[k];
        void *mem = q->ports[k].mem;
        uint32_t tail = atomic_load(&d->rx_tail);
        if (ske_queue_count(mem, pc->max_nb, tail) == UINT32_MAX) {
            /* the reader corrupted its consumer index: resynchronise it */
            atomic_store(&d->rx_tail, atomic_load(&((ske_queue_hdr_t *)mem)->head));
            tail = atomic_load(&d->rx_tail);
        }
        if (!ske_queue_push(mem, pc->max_size, pc->max_nb, tail, &e, sizeof e, t)) {
            /* A reader that does not keep up loses decisions, never delays the module. */
            atomic_fetch_add(&((ske_queue_hdr_t *)mem)->overflows, 1);
            q->hm_log_lost++;
        }
    }
}
