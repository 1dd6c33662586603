/* SPDX-License-Identifier: Apache-2.0 */
/* Health-monitor decisions applied: the SKE takes what a partition posted and what it
 * detects itself (window overrun, partition exit), has hm_decide decide, traces the decision
 * and applies it (idle, restart, module reset or shutdown). */
#include "ske__supervisor.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

/* The system state a partition is in, as far as the SKE can tell. */
hm_state_t ske__partition_state(const ske_part_t *p)
{
    uint32_t mode = p->ctl ? atomic_load(&p->ctl->mode) : SKE_MODE_COLD_START;
    return mode == SKE_MODE_NORMAL ? HM_STATE_PROCESS : HM_STATE_PARTITION_INIT;
}

/* Writes an hm event's fields; the caller ends it (ske_trace_end). */
void ske__trace_hm_fields(ske_t *s, int64_t t, const ske_part_t *p, hm_error_t err,
                          hm_level_t level, hm_action_t action, hm_state_t state,
                          int32_t process, const char *pname, const char *message, size_t mlen,
                          const char *note)
{
    s->hm_events++;
    ske_trace_begin(&s->trace, t, level == HM_LEVEL_PROCESS ? p->cfg->name : "ske", "hm");
    ske_trace_str(&s->trace, "error", hm_error_name(err));
    ske_trace_str(&s->trace, "level", hm_level_name(level));
    ske_trace_str(&s->trace, "action", hm_action_name(action));
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    if (pname)
        ske_trace_str(&s->trace, "process", pname);
    else
        ske_trace_raw(&s->trace, "process", "null");
    ske_trace_int(&s->trace, "process_id", process);
    ske_trace_str(&s->trace, "state", hm_state_name(state));
    ske_trace_int(&s->trace, "error_code", hm_apex_error_code(err));
    if (message && mlen)
        ske_trace_strn(&s->trace, "message", message, mlen);
    if (note)
        ske_trace_str(&s->trace, "note", note);
    ske__hm_log_publish(s, t, p, err, level, action, state, process, pname, message, mlen);
}

static void trace_hm(ske_t *s, int64_t t, const ske_part_t *p, hm_error_t err, hm_level_t level,
                     hm_action_t action, hm_state_t state, int32_t process, const char *pname,
                     const char *message, size_t mlen, const char *note)
{
    ske__trace_hm_fields(s, t, p, err, level, action, state, process, pname, message, mlen, note);
    ske_trace_end(&s->trace);
}

/* A partition-level action of the Partition HM table (ARINC 653 Part 1, 2.4.2). */
static int apply_partition_action(ske_t *s, ske_part_t *p, hm_action_t action, int64_t t, char *err,
                                  size_t errlen)
{
    uint32_t cur = p->ctl ? atomic_load(&p->ctl->mode) : SKE_MODE_NORMAL;
    switch (action) {
    case HM_ACT_IDLE:
        ske__kill_partition(p);
        p->state = SKE_PS_IDLE;
        ske__trace_mode(s, p, t, SKE_MODE_IDLE, cur, "health monitor");
        return SKE_OK;
    case HM_ACT_WARM_START:
    case HM_ACT_COLD_START: {
        uint32_t mode = action == HM_ACT_WARM_START ? SKE_MODE_WARM_START : SKE_MODE_COLD_START;
        ske__kill_partition(p);
        ske__trace_mode(s, p, t, mode, cur, "health monitor");
        p->start_condition = 3; /* HM_PARTITION_RESTART */
        p->initial_mode = mode;
        p->restarts++;
        p->state = SKE_PS_NOT_STARTED;
        return ske__respawn(s, p, t);
    }
    default:
        return SKE_OK;
    }
}

/* Applies the health monitor's decision on an error that reached the SKE: the partition could
 * not handle it, or the SKE detected it itself. The decision is hm_decide's, from the SKE's own
 * copy of the tables, never from the partition's. */
int ske__hm_handle(ske_t *s, ske_part_t *p, int64_t t, hm_error_t e, hm_state_t state,
                   hm_origin_t origin, int32_t process, const char *pname, const char *msg,
                   size_t mlen, bool fatal, char *err, size_t errlen)
{
    /* Whatever reaches the SKE no error handler could take. A partition already ended has no
     * context left that could hang. */
    hm_decision_t d = hm_decide(&s->cfg->hm, &p->cfg->hm, state, e, origin, false,
                                fatal && ske__alive(p));
    /* Test switch hm-action: another action than the tables', traced as applied. */
    hm_action_t forced;
    if (d.level == HM_LEVEL_PARTITION && ske__switch_hm_action(s, p, &forced)) {
        d.action = d.partition_action = forced;
        d.note = NULL;
    }
    /* A module decision is the module's; what it leaves to the partition is told apart. */
    bool module_note = d.level == HM_LEVEL_MODULE && d.note;
    trace_hm(s, t, p, e, d.level, d.action, state, process, pname, msg, mlen,
             module_note ? NULL : d.note);
    if (d.level == HM_LEVEL_MODULE && d.action == HM_ACT_SHUTDOWN)
        s->hm_shutdown = true;
    else if (d.level == HM_LEVEL_MODULE && d.action == HM_ACT_RESET)
        s->hm_reset = true;
    if (module_note) {
        ske_trace_begin(&s->trace, t, "ske", "hm_note");
        ske_trace_str(&s->trace, "partition", p->cfg->name);
        ske_trace_str(&s->trace, "note", d.note);
        ske_trace_end(&s->trace);
    }
    return apply_partition_action(s, p, d.partition_action, t, err, errlen);
}

/* An error the partition posted (partition or module level). Every field is checked. */
int ske__hm_take_post(ske_t *s, ske_part_t *p, int64_t t, char *err, size_t errlen)
{
    ske_ctl_t *c = p->ctl;
    uint32_t seq = atomic_load(&c->hm_seq);
    if (seq == atomic_load(&c->hm_ack))
        return SKE_OK;
    hm_error_t e = (hm_error_t)c->hm_error;
    hm_state_t st = (hm_state_t)c->hm_state;
    char pname[SKE_NAME_MAX], msg[SKE_EVENT_TEXT];
    memcpy(pname, c->hm_process_name, sizeof pname);
    pname[sizeof pname - 1] = '\0';
    size_t mlen = c->hm_len < sizeof msg ? c->hm_len : sizeof msg;
    memcpy(msg, c->hm_message, mlen);
    int32_t process = c->hm_process;
    bool fatal = c->hm_fatal != 0;
    atomic_store(&c->hm_ack, seq); /* the partition goes on once the action is decided */
    if (!hm_error_name(e) || !hm_state_name(st) || e == HM_ERR_WINDOW_OVERRUN || e == HM_ERR_PARTITION_EXIT)
        return SKE_OK; /* not an error a partition can report */
    /* The failed process's name; none for the initialisation process (the error handler,
     * whose identifier is 0 too, has one). */
    hm_origin_t origin = !pname[0]     ? HM_ORIGIN_PARTITION
                         : process == 0 ? HM_ORIGIN_ERROR_HANDLER
                                        : HM_ORIGIN_PROCESS;
    return ske__hm_handle(s, p, t, e, st, origin, process, pname[0] ? pname : NULL, msg, mlen,
                          fatal, err, errlen);
}

/* Applies a pending module RESET: every partition starts again (ARINC 653 Part 1, 2.4.2). */
int ske__hm_module_reset(ske_t *s, int64_t t, char *err, size_t errlen)
{
    s->hm_reset = false;
    for (int i = 0; i < s->cfg->n_partitions; i++) {
        ske_part_t *p = &s->parts[i];
        uint32_t cur = p->ctl ? atomic_load(&p->ctl->mode) : SKE_MODE_IDLE;
        ske__kill_partition(p);
        ske__trace_mode(s, p, t, SKE_MODE_COLD_START, cur, "module reset");
        p->start_condition = 2; /* HM_MODULE_RESTART */
        p->initial_mode = SKE_MODE_COLD_START;
        p->restarts++;
        p->state = SKE_PS_NOT_STARTED;
        ske__respawn(s, p, t);
    }
    (void)err;
    (void)errlen;
    return SKE_OK;
}

/* A partition whose process ended without being asked to: PARTITION_EXIT. */
int ske__judge_exits(ske_t *s, int64_t t, char *err, size_t errlen)
{
    for (int i = 0; i < s->cfg->n_partitions; i++) {
        ske_part_t *p = &s->parts[i];
        if (!p->exit_to_judge)
            continue;
        p->exit_to_judge = false;
        int rc = SKE_OK;
        if (p->ctl)
            rc = ske__hm_take_post(s, p, t, err, errlen); /* what it reported before it ended */
        if (rc != SKE_OK)
            return rc;
        if (p->state != SKE_PS_EXITED && p->state != SKE_PS_CRASHED)
            continue; /* the health monitor already idled or restarted it */
        char msg[64];
        int n = p->state == SKE_PS_CRASHED
                    ? snprintf(msg, sizeof msg, "killed by SIG%s",
                               sigabbrev_np(p->exit_code) ? sigabbrev_np(p->exit_code) : "?")
                    : snprintf(msg, sizeof msg, "exited with status %d", p->exit_code);
        rc = ske__hm_handle(s, p, t, HM_ERR_PARTITION_EXIT, ske__partition_state(p),
                            HM_ORIGIN_SKE, 0, NULL, msg, (size_t)n, false, err, errlen);
        if (rc != SKE_OK)
            return rc;
    }
    return SKE_OK;
}
