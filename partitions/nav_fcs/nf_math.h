/* SPDX-License-Identifier: Apache-2.0 */
/* Small numeric helpers of the nav_fcs core: angle wrapping, limits, rate limits, ISA density. */
#ifndef NF_MATH_H
#define NF_MATH_H

#include <math.h>

#define NF_PI 3.14159265358979323846
#define NF_DEG (NF_PI / 180.0)
#define NF_G_MPS2 9.80665
#define NF_KT_MPS 0.514444         /* 1 kt in m/s */
#define NF_KT_FPM 101.268591       /* 1 kt in ft/min */
#define NF_EARTH_R_M 6371008.8     /* mean Earth radius */

static inline double nf_clamp(double x, double lo, double hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

/* An angle in degrees brought into [-180, 180). */
static inline double nf_wrap180(double a)
{
    double w = fmod(a + 180.0, 360.0);
    if (w < 0.0)
        w += 360.0;
    return w - 180.0;
}

/* An angle in degrees brought into [0, 360). */
static inline double nf_wrap360(double a)
{
    double w = fmod(a, 360.0);
    if (w < 0.0)
        w += 360.0;
    return w >= 360.0 ? 0.0 : w;
}

/* Moves x towards target by at most rate * dt. */
static inline double nf_rate_limit(double x, double target, double rate, double dt)
{
    double step = rate * dt;
    return x + nf_clamp(target - x, -step, step);
}

/* ISA density ratio sigma = rho / rho0 at a pressure altitude (troposphere, ICAO Doc 7488). */
static inline double nf_isa_sigma(double alt_ft)
{
    double h = nf_clamp(alt_ft, -2000.0, 36000.0);
    double theta = 1.0 - 6.8755856e-6 * h; /* T / T0 */
    return pow(theta, 4.2558797);
}

/* True airspeed from indicated (taken as equivalent) airspeed at a pressure altitude. */
static inline double nf_tas_from_ias(double ias_kt, double alt_ft)
{
    return ias_kt / sqrt(nf_isa_sigma(alt_ft));
}

#endif /* NF_MATH_H */
