/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the nav_fcs numeric helpers: angle wrapping, limits, ISA true airspeed. */
#include "nf_math.h"
#include "rpas/unit_check.h"

static void test_wrap180(void)
{
    CHECK_NEAR(nf_wrap180(0.0), 0.0, 1e-12);
    CHECK_NEAR(nf_wrap180(190.0), -170.0, 1e-12);
    CHECK_NEAR(nf_wrap180(-190.0), 170.0, 1e-12);
    CHECK_NEAR(nf_wrap180(180.0), -180.0, 1e-12);
    CHECK_NEAR(nf_wrap180(-180.0), -180.0, 1e-12);
    CHECK_NEAR(nf_wrap180(540.0), -180.0, 1e-12);
    CHECK_NEAR(nf_wrap180(719.0), -1.0, 1e-9);
    CHECK_NEAR(nf_wrap180(-1079.0), 1.0, 1e-9);
    /* heading error across north: target 10, heading 350 -> +20 (turn right) */
    CHECK_NEAR(nf_wrap180(10.0 - 350.0), 20.0, 1e-12);
    CHECK_NEAR(nf_wrap180(350.0 - 10.0), -20.0, 1e-12);
}

static void test_wrap360(void)
{
    CHECK_NEAR(nf_wrap360(-10.0), 350.0, 1e-12);
    CHECK_NEAR(nf_wrap360(360.0), 0.0, 1e-12);
    CHECK_NEAR(nf_wrap360(725.0), 5.0, 1e-12);
    CHECK_NEAR(nf_wrap360(-720.0), 0.0, 1e-12);
    double w = nf_wrap360(-1e-17); /* rounds to 360 in fmod arithmetic: must still be < 360 */
    CHECK(w >= 0.0 && w < 360.0);
}

static void test_limits(void)
{
    CHECK_NEAR(nf_clamp(5.0, -1.0, 1.0), 1.0, 0.0);
    CHECK_NEAR(nf_clamp(-5.0, -1.0, 1.0), -1.0, 0.0);
    CHECK_NEAR(nf_clamp(0.25, -1.0, 1.0), 0.25, 0.0);
    CHECK_NEAR(nf_rate_limit(0.0, 10.0, 2.0, 0.5), 1.0, 1e-12);
    CHECK_NEAR(nf_rate_limit(0.0, -10.0, 2.0, 0.5), -1.0, 1e-12);
    CHECK_NEAR(nf_rate_limit(0.0, 0.3, 2.0, 0.5), 0.3, 1e-12);
}

static void test_isa(void)
{
    CHECK_NEAR(nf_isa_sigma(0.0), 1.0, 1e-12);
    CHECK_NEAR(nf_isa_sigma(10000.0), 0.7385, 0.001); /* ISA table */
    CHECK_NEAR(nf_isa_sigma(5000.0), 0.8617, 0.001);
    /* 100 KIAS at 3000 ft is about 104.5 KTAS */
    CHECK_NEAR(nf_tas_from_ias(100.0, 3000.0), 104.5, 0.2);
}

int main(void)
{
    RUN(test_wrap180);
    RUN(test_wrap360);
    RUN(test_limits);
    RUN(test_isa);
    return UNIT_RESULT();
}
