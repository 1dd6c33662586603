/* SPDX-License-Identifier: Apache-2.0 */
/* The mission manager's geometry: a local flat-earth frame about the plan's origin (metres
 * north and east; good to a few metres over the tens of kilometres of a mission), segments and
 * where the aircraft is against them, hold entry sectors, turn radii, Dubins paths. */
#include <math.h>

#include "mm.h"
#include "nf_math.h"

void mm_frame_init(mm_frame_t *f, double lat0_deg, double lon0_deg)
{
    f->lat0_deg = lat0_deg;
    f->lon0_deg = lon0_deg;
    f->coslat0 = cos(lat0_deg * NF_DEG);
}

mm_vec_t mm_to_local(const mm_frame_t *f, double lat_deg, double lon_deg)
{
    return (mm_vec_t){(lat_deg - f->lat0_deg) * NF_DEG * NF_EARTH_R_M,
                      nf_wrap180(lon_deg - f->lon0_deg) * NF_DEG * NF_EARTH_R_M * f->coslat0};
}

mm_vec_t mm_from_e7(const mm_frame_t *f, int32_t lat_e7, int32_t lon_e7)
{
    return mm_to_local(f, lat_e7 * 1e-7, lon_e7 * 1e-7);
}

mm_vec_t mm_vec(double course_deg, double len_m)
{
    return (mm_vec_t){len_m * cos(course_deg * NF_DEG), len_m * sin(course_deg * NF_DEG)};
}

double mm_course(mm_vec_t from, mm_vec_t to)
{
    return nf_wrap360(atan2(to.e - from.e, to.n - from.n) / NF_DEG);
}

double mm_dist(mm_vec_t a, mm_vec_t b)
{
    return hypot(b.n - a.n, b.e - a.e);
}

mm_vec_t mm_add(mm_vec_t a, mm_vec_t b)
{
    return (mm_vec_t){a.n + b.n, a.e + b.e};
}

mm_vec_t mm_sub(mm_vec_t a, mm_vec_t b)
{
    return (mm_vec_t){a.n - b.n, a.e - b.e};
}

mm_vec_t mm_scale(mm_vec_t a, double k)
{
    return (mm_vec_t){a.n * k, a.e * k};
}

mm_seg_t mm_line(mm_vec_t a, mm_vec_t b)
{
    return (mm_seg_t){.kind = MM_SEG_LINE, .a = a, .b = b, .crs = mm_course(a, b)};
}

mm_seg_t mm_arc(mm_vec_t centre, double r, int dir)
{
    return (mm_seg_t){.kind = MM_SEG_ARC, .c = centre, .r = r, .dir = dir < 0 ? -1 : 1};
}

mm_track_t mm_track(const mm_seg_t *s, mm_vec_t p)
{
    mm_track_t t = {0};
    if (s->kind == MM_SEG_LINE) {
        double len = mm_dist(s->a, s->b);
        double c = cos(s->crs * NF_DEG), sn = sin(s->crs * NF_DEG);
        mm_vec_t d = mm_sub(p, s->a);
        t.path_crs = s->crs;
        t.along_m = d.n * c + d.e * sn;
        t.xte_m = -d.n * sn + d.e * c;
        t.to_go_m = len - t.along_m;
    } else if (s->kind == MM_SEG_ARC) {
        double rho = mm_dist(s->c, p);
        double bearing = mm_course(s->c, p); /* from the centre */
        t.path_crs = nf_wrap360(bearing + 90.0 * s->dir);
        t.xte_m = s->dir * (s->r - rho);
    } else {
        t.path_crs = s->crs;
    }
    return t;
}

int mm_hold_entry(double heading_deg, double inbound_deg, int dir)
{
    /* d: the heading against the inbound course, mirrored for left-hand holds, in [0, 360). */
    double d = nf_wrap360((heading_deg - inbound_deg) * (dir < 0 ? -1.0 : 1.0));
    if (d <= 70.0 || d >= 250.0)
        return MM_ENTRY_DIRECT; /* 180 degrees: arriving from the holding side */
    if (d <= 180.0)
        return MM_ENTRY_PARALLEL; /* 110 degrees on the non-holding side */
    return MM_ENTRY_TEARDROP;     /* the 70 degrees between */
}

double mm_turn_radius(double gs_mps, double bank_deg)
{
    double v = gs_mps > 20.0 ? gs_mps : 20.0;
    return v * v / (NF_G_MPS2 * tan(nf_clamp(bank_deg, 5.0, 45.0) * NF_DEG));
}

double mm_hold_radius(double tas_mps, double rate_dps, double max_bank_deg)
{
    double v = tas_mps > 20.0 ? tas_mps : 20.0;
    double bank = atan(v * rate_dps * NF_DEG / NF_G_MPS2) / NF_DEG;
    return mm_turn_radius(v, bank < max_bank_deg ? bank : max_bank_deg);
}

/* The centre of the turn circle of pose (p, crs) turning dir. */
static mm_vec_t turn_centre(mm_vec_t p, double crs, int dir, double r)
{
    return mm_add(p, mm_vec(crs + 90.0 * dir, r));
}

/* Arc length turning dir from course c0 to course c1 on radius r. */
static double arc_len(double c0, double c1, int dir, double r)
{
    return nf_wrap360((c1 - c0) * dir) * NF_DEG * r;
}

bool mm_dubins(mm_vec_t p0, double crs0, mm_vec_t p1, double crs1, double r, mm_dubins_t *out)
{
    static const int dirs[4][2] = {{1, 1}, {-1, -1}, {1, -1}, {-1, 1}}; /* RSR LSL RSL LSR */
    bool found = false;
    for (int k = 0; k < 4; k++) {
        int d1 = dirs[k][0], d2 = dirs[k][1];
        mm_vec_t c1 = turn_centre(p0, crs0, d1, r), c2 = turn_centre(p1, crs1, d2, r);
        double dist = mm_dist(c1, c2);
        double base = mm_course(c1, c2);
        double crs; /* the straight's course */
        if (d1 == d2) {
            crs = base;
        } else {
            if (dist < 2.0 * r)
                continue;
            /* inner tangent: the straight leaves c1's circle at angle asin(2r / dist) */
            crs = base + d1 * asin(2.0 * r / dist) / NF_DEG;
        }
        mm_vec_t t1 = mm_add(c1, mm_vec(crs - 90.0 * d1, r));
        mm_vec_t t2 = mm_add(c2, mm_vec(crs - 90.0 * d2, r));
        double len = arc_len(crs0, crs, d1, r) + mm_dist(t1, t2) + arc_len(crs, crs1, d2, r);
        if (!found || len < out->length_m) {
            found = true;
            out->arc1 = mm_arc(c1, r, d1);
            out->arc1.crs = nf_wrap360(crs);
            out->line = mm_line(t1, t2);
            out->line.crs = nf_wrap360(crs);
            out->arc2 = mm_arc(c2, r, d2);
            out->arc2.crs = nf_wrap360(crs1);
            out->t1 = t1;
            out->t2 = t2;
            out->length_m = len;
        }
    }
    return found;
}
