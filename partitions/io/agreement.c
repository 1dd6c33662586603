/* SPDX-License-Identifier: Apache-2.0 */
/* io's input agreement: the sensor samples this node exchanges with the others over DDS, and
 * the agreed inputs it feeds nav_fcs in their place, so that healthy replicas compute from the
 * same data. For each sensor: the newest sample any member holds (within the bounds of
 * in_bounds), its values voted (ima voter: median of 3, average of 2) over the members that
 * hold that same sample. */
#include <string.h>

#include "io_core.h"

#define NODE_BIT(k) (1u << (k))

enum { IN_GPS, IN_AHRS, IN_AIR };
static const unsigned dims[3] = {5, 9, 3};

void io_inputs(const io_rx_t *rx, struct xch_inputs *in)
{
    memset(in, 0, sizeof *in);
    if (rx->gps.t_ns > 0) {
        const rpas_gps_msg_t *g = &rx->gps;
        in->valid |= XCH_IN_GPS;
        in->gps_t_ns = g->t_ns;
        in->gps_seq = g->seq;
        in->gps_fix = g->fix;
        in->gps_sats = g->sats;
        double v[5] = {g->lat_deg, g->lon_deg, g->alt_ft, g->gs_kt, g->trk_deg};
        memcpy(in->gps, v, sizeof v);
    }
    if (rx->ahrs.t_ns > 0) {
        const rpas_ahrs_msg_t *a = &rx->ahrs;
        in->valid |= XCH_IN_AHRS;
        in->ahrs_t_ns = a->t_ns;
        in->ahrs_seq = a->seq;
        in->ahrs_status = a->status;
        double v[9] = {a->roll_deg, a->pitch_deg, a->hdg_deg, a->p_dps, a->q_dps,
                       a->r_dps,    a->ax_g,      a->ay_g,    a->az_g};
        memcpy(in->ahrs, v, sizeof v);
    }
    if (rx->air.t_ns > 0) {
        const rpas_air_msg_t *a = &rx->air;
        in->valid |= XCH_IN_AIR;
        in->air_t_ns = a->t_ns;
        in->air_seq = a->seq;
        in->air_status = a->status;
        double v[3] = {a->ias_kt, a->alt_ft, a->vs_fpm};
        memcpy(in->air, v, sizeof v);
    }
}

/* Sensor `which` of a node's inputs: false if it holds none. */
static bool sample_of(const struct xch_inputs *in, unsigned which, int64_t *t, uint32_t *seq,
                      const double **values)
{
    static const uint32_t bit[3] = {XCH_IN_GPS, XCH_IN_AHRS, XCH_IN_AIR};
    if (!(in->valid & bit[which]))
        return false;
    *t = which == IN_GPS ? in->gps_t_ns : which == IN_AHRS ? in->ahrs_t_ns : in->air_t_ns;
    *seq = which == IN_GPS ? in->gps_seq : which == IN_AHRS ? in->ahrs_seq : in->air_seq;
    *values = which == IN_GPS ? in->gps : which == IN_AHRS ? in->ahrs : in->air;
    return true;
}

/* Whether a member's sample stamped t may take part in the frame starting at now: not
 * stamped after the frame's end (no node can have received it yet), not older than the
 * port's refresh period (stale). A member that sends such stamps is faulty or forged: the
 * newest sample would otherwise win whatever the others hold. */
static bool in_bounds(io_red_t *red, unsigned k, unsigned which, int64_t t, int64_t now)
{
    if (red->max_age_ns[which] <= 0)
        return true;
    if (t <= now + red->frame_ns && now - t <= red->max_age_ns[which])
        return true;
    red->refused_stamps[k]++;
    red->refused_new |= NODE_BIT(k);
    return false;
}

/* One sensor's agreed sample: the newest any member holds within the bounds; its values voted
 * over the members that hold that same sample. Returns the node (0..2) whose copy carries the
 * sample's other fields, or -1 if no member holds one. */
static int agree(io_red_t *red, const struct xch_agreed *ag, unsigned which, int64_t now,
                 double *out)
{
    int64_t t, newest = -1;
    uint32_t seq, newest_seq = 0;
    const double *values;
    int carrier = -1;
    uint32_t usable = 0;
    for (unsigned k = 0; k < red->n_nodes; k++)
        if ((ag->present & NODE_BIT(k)) && sample_of(&ag->in[k], which, &t, &seq, &values) &&
            in_bounds(red, k, which, t, now))
            usable |= NODE_BIT(k);
    for (unsigned k = 0; k < red->n_nodes; k++)
        if ((usable & NODE_BIT(k)) && sample_of(&ag->in[k], which, &t, &seq, &values) &&
            t > newest) {
            newest = t;
            newest_seq = seq;
            carrier = (int)k;
        }
    if (carrier < 0)
        return -1;
    double x[VOTER_MAX_CH][VOTER_MAX_DIM] = {{0}};
    uint8_t present = 0;
    for (unsigned k = 0; k < red->n_nodes; k++)
        if ((usable & NODE_BIT(k)) && sample_of(&ag->in[k], which, &t, &seq, &values) &&
            t == newest && seq == newest_seq) {
            memcpy(x[k], values, dims[which] * sizeof(double));
            present |= (uint8_t)NODE_BIT(k);
        }
    voter_out_t o;
    voter_step(&red->in_vote[which], (const double(*)[VOTER_MAX_DIM])x, present, &o);
    memcpy(out, o.value, dims[which] * sizeof *out);
    return carrier;
}

void io_apply_agreed(io_red_t *red, io_rx_t *rx, const struct xch_agreed *ag, int64_t now)
{
    double v[VOTER_MAX_DIM];
    int k;
    if ((k = agree(red, ag, IN_GPS, now, v)) >= 0 && ag->in[k].gps_t_ns > rx->last_gps_t) {
        const struct xch_inputs *c = &ag->in[k];
        rpas_gps_msg_t *g = &rx->gps;
        g->t_ns = c->gps_t_ns;
        g->seq = c->gps_seq;
        g->fix = c->gps_fix;
        g->sats = c->gps_sats;
        g->lat_deg = v[0], g->lon_deg = v[1], g->alt_ft = v[2], g->gs_kt = v[3], g->trk_deg = v[4];
        rx->gps_new = true;
    }
    if ((k = agree(red, ag, IN_AHRS, now, v)) >= 0 && ag->in[k].ahrs_t_ns > rx->last_ahrs_t) {
        const struct xch_inputs *c = &ag->in[k];
        rpas_ahrs_msg_t *a = &rx->ahrs;
        a->t_ns = c->ahrs_t_ns;
        a->seq = c->ahrs_seq;
        a->status = c->ahrs_status;
        a->roll_deg = v[0], a->pitch_deg = v[1], a->hdg_deg = v[2];
        a->p_dps = v[3], a->q_dps = v[4], a->r_dps = v[5];
        a->ax_g = v[6], a->ay_g = v[7], a->az_g = v[8];
        rx->ahrs_new = true;
    }
    if ((k = agree(red, ag, IN_AIR, now, v)) >= 0 && ag->in[k].air_t_ns > rx->last_air_t) {
        const struct xch_inputs *c = &ag->in[k];
        rpas_air_msg_t *a = &rx->air;
        a->t_ns = c->air_t_ns;
        a->seq = c->air_seq;
        a->status = c->air_status;
        a->ias_kt = v[0], a->alt_ft = v[1], a->vs_fpm = v[2];
        rx->air_new = true;
    }
}

bool io_mission_due(io_red_t *red, const rpas_pilot_msg_t *pilot, uint32_t frame,
                    struct xch_mission *out)
{
    if (!pilot->have_targets)
        return false;
    struct xch_mission m = {.mode = pilot->mode, .lat_mode = pilot->lat_mode,
                            .vert_mode = pilot->vert_mode, .hdg_deg = pilot->hdg_deg,
                            .alt_ft = pilot->alt_ft, .ias_kt = pilot->ias_kt,
                            .vs_fpm = pilot->vs_fpm};
    /* when the targets change, and once a second */
    if (red->mission_sent && !memcmp(&m, &red->last_mission, sizeof m) &&
        frame - red->last_mission_frame < 20)
        return false;
    red->last_mission = m;
    red->last_mission_frame = frame;
    red->mission_sent = true;
    *out = m;
    return true;
}
