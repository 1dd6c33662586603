/* SPDX-License-Identifier: Apache-2.0 */
/* The guidance layer: from the sequencing layer's demand (a segment, an altitude reference,
 * an airspeed) to the targets nav_fcs flies (TRK or HDG, VS, SPD), within the plan's envelope.
 *
 * Lateral: a vector field about the path (the approach angle falls smoothly from chi_inf far
 * from it to zero on it, so the course demanded never jumps and the path is joined without
 * overshoot); arcs add their turn rate as a lead, since nav_fcs's track loop lags. When the
 * wind nears the airspeed a track can no longer be flown (the aircraft would be blown
 * backwards or stall its turn): the demanded course is then flown as a heading, which stays
 * safe, and the path is rejoined when the wind drops.
 *
 * Vertical: the energy logic of TECS at target level. The altitude error gives the climb rate
 * (potential-energy rate) the path wants; the airspeed error shifts energy between speed and
 * height (the energy balance): short of airspeed, the climb gives way (or the descent
 * steepens) before nav_fcs's throttle runs out; fast in a descent, the descent flattens. The
 * inner loops (pitch, throttle) stay in nav_fcs. */
#include <math.h>

#include "mm.h"
#include "nf_math.h"

double mm_lateral(const mm_params_t *prm, const mm_seg_t *s, const mm_track_t *tk, double gs_mps)
{
    if (s->kind == MM_SEG_HDG || s->kind == MM_SEG_TURN)
        return s->crs;
    double approach = prm->chi_inf_deg * (2.0 / NF_PI) * atan(tk->xte_m / prm->xte_scale_m);
    double lead = 0.0;
    if (s->kind == MM_SEG_ARC && s->r > 1.0)
        lead = s->dir * (gs_mps / s->r) / NF_DEG * prm->arc_lead_s;
    return nf_wrap360(tk->path_crs - approach + lead);
}

void mm_guidance(const mm_params_t *prm, const rpas_plan_header_t *hdr, const mm_state_t *st,
                 const mm_demand_t *d, uint32_t mode, rpas_mission_msg_t *out)
{
    out->mode = mode;
    bool windy = st->tas_mps > 1.0 && st->wind_mps > prm->wind_hdg_ratio * st->tas_mps;
    out->lat_mode = d->hdg || windy ? RPAS_LAT_HDG : RPAS_LAT_TRK;
    out->hdg_deg = nf_wrap360(d->crs_deg);

    double ias = isfinite(d->ias_kt) ? d->ias_kt : hdr->cruise_ias_kt;
    ias = nf_clamp(ias, hdr->min_ias_kt, hdr->max_ias_kt);
    out->ias_kt = ias;

    double vs_max = hdr->max_vs_fpm;
    double vs = d->vs_ff_fpm + prm->alt_kp * (d->alt_ft - st->alt_ft);
    /* energy balance: an airspeed deficit takes from the climb, an excess from the descent */
    double dv = ias - st->ias_kt;
    if (d->raw_vs)
        ; /* the flare trades its speed away on purpose */
    else if (dv > prm->energy_dead_kt && vs > -vs_max)
        vs -= prm->energy_kb * (dv - prm->energy_dead_kt);
    else if (dv < -prm->energy_dead_kt && vs < 0.0)
        vs = fmin(0.0, vs - prm->energy_kb * (dv + prm->energy_dead_kt));
    out->vert_mode = RPAS_VERT_VS;
    out->vs_fpm = nf_clamp(vs, -vs_max, vs_max);
    out->alt_ft = d->alt_ft;
}
