/* SPDX-License-Identifier: Apache-2.0 */
/* io's view of the other replicas: node membership from the CAN heartbeats, and the
 * self-monitor that votes the replicas' commands as the actuators do.
 *
 * Membership: node k is a member while its heartbeat (FCS_STATUS on its redundancy channel)
 * keeps coming; `misses` major frames without one remove it, latched. Every node sees the same
 * broadcast bus at the same instants, so every node computes the same membership: it is agreed
 * without a protocol of its own.
 *
 * Self-monitor: the replicas' last commands, voted with the ima voter and the system's
 * thresholds; this node's own command voted out is a fault of this replica, which main.c
 * reports to its health monitor. */
#include <stdio.h>
#include <string.h>

#include "io_core.h"

#define NODE_BIT(k) (1u << (k)) /* k: channel index 0..2 */

int io_red_init(io_red_t *red, const io_settings_t *s)
{
    memset(red, 0, sizeof *red);
    red->n_nodes = s->n_nodes;
    red->channel = s->channel;
    red->misses = s->membership_misses;
    red->members = s->node_mask;
    voter_cfg_t vc = {.n = s->n_nodes, .dim = IO_AXES, .persist = s->vote_persist};
    memcpy(vc.threshold, s->vote_threshold, sizeof s->vote_threshold);
    red->selfmon_on = s->n_nodes > 1;
    if (red->selfmon_on && voter_init(&red->selfmon, &vc) != 0)
        return -1;
    /* Input voting: thresholds wide enough for two copies of one sample (they agree exactly
     * when healthy); a miscompare only marks that node's copy out of the vote. */
    static const unsigned dims[3] = {5, 9, 3};
    for (int i = 0; i < 3; i++) {
        voter_cfg_t ic = {.n = s->n_nodes, .dim = dims[i], .persist = 1000000000u};
        for (unsigned d = 0; d < dims[i]; d++)
            ic.threshold[d] = 1e9;
        if (voter_init(&red->in_vote[i], &ic) != 0)
            return -1;
    }
    return 0;
}

uint32_t io_membership_update(io_red_t *red)
{
    uint32_t before = red->members;
    for (unsigned k = 0; k < red->n_nodes; k++) {
        if (k == red->channel || !(red->members & NODE_BIT(k)))
            continue;
        if (red->peers.hb_seen & NODE_BIT(k))
            red->hb_missed[k] = 0;
        else if (++red->hb_missed[k] >= red->misses)
            red->members &= ~NODE_BIT(k);
    }
    red->peers.hb_seen = 0;
    return before & ~red->members;
}

void io_self_monitor(io_red_t *red, io_monitor_t *out)
{
    memset(out, 0, sizeof *out);
    if (red->selfmon_on && red->own_cmd.have) {
        double x[VOTER_MAX_CH][VOTER_MAX_DIM] = {{0}};
        uint8_t present = 0;
        for (unsigned k = 0; k < red->n_nodes; k++) {
            bool mine = k == red->channel;
            if (mine || (red->peers.cmd[k].have && (red->members & NODE_BIT(k)))) {
                memcpy(x[k], mine ? red->own_cmd.v : red->peers.cmd[k].v, IO_AXES * sizeof(double));
                present |= (uint8_t)NODE_BIT(k);
            }
        }
        voter_out_t vo;
        voter_step(&red->selfmon, (const double(*)[VOTER_MAX_DIM])x, present, &vo);
        for (unsigned k = 0; k < red->n_nodes; k++) {
            if (!(vo.newly_failed & NODE_BIT(k)))
                continue;
            out->newly_failed |= NODE_BIT(k);
            out->reason[k] = voter_reason_name((voter_reason_t)red->selfmon.reason[k]);
            if (k == red->channel) {
                red->own_voted_out = true;
                out->own_out = true;
            } else {
                red->peers_voted_out |= NODE_BIT(k);
            }
        }
        out->disagree = vo.newly_disagree;
    }
    /* nothing of ours to compare yet (start-up), or done: the next frame starts afresh */
    red->own_cmd.have = false;
    for (unsigned k = 0; k < XCH_MAX_NODES; k++)
        red->peers.cmd[k].have = false;
}

void io_health(const io_red_t *red, uint32_t fcs_mode, struct xch_health *h)
{
    memset(h, 0, sizeof *h);
    h->membership = red->members;
    h->fcs_mode = fcs_mode;
    h->failed = red->peers_voted_out | (red->own_voted_out ? NODE_BIT(red->channel) : 0);
    h->flags = red->own_voted_out ? XCH_HEALTH_DISAGREE : 0;
}

bool io_health_due(io_red_t *red, const struct xch_health *h, uint32_t frame)
{
    if (red->health_sent && !memcmp(h, &red->last_health, sizeof *h) &&
        frame - red->last_health_frame < IO_HEALTH_REFRESH_FRAMES)
        return false;
    red->last_health = *h;
    red->last_health_frame = frame;
    red->health_sent = true;
    return true;
}

void io_node_list(uint32_t mask, unsigned n_nodes, char *buf, size_t len)
{
    size_t at = 0;
    buf[0] = 0;
    for (unsigned k = 0; k < n_nodes && at < len; k++)
        if (mask & NODE_BIT(k))
            at += (size_t)snprintf(buf + at, len - at, "%snode%u", at ? "," : "", k + 1);
}
