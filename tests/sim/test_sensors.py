# SPDX-License-Identifier: Apache-2.0
"""Sensor models: error statistics roughly as configured, deterministic for a seed."""

from __future__ import annotations

import math
import statistics

import pytest

from ima.canbus.codec import MESSAGES
from imaworld.config import AdcParams, AhrsParams, GpsParams
from imaworld.sensors import AirData, Ahrs, GaussMarkov, Gps, normal_stream

LAT, LON = 47.0, 8.0
M_PER_DEG = 6_378_137.0 * math.pi / 180


def _diff_std(xs):
    """std of successive differences / sqrt(2): the white part of the noise (biases wander
    slowly compared with the sample period)."""
    return statistics.pstdev([b - a for a, b in zip(xs, xs[1:])]) / math.sqrt(2)


def _gps_run(seed, n=3000, state="ok"):
    g = Gps(GpsParams(), seed)
    g.state = state
    out = []
    for _ in range(n):
        frames = g.sample(LAT, LON, 3000.0, 100.0, 150.0)
        out.append(frames)
    return out


def test_gps_noise_and_bias():
    pos, vel = MESSAGES["GPS_POS"], MESSAGES["GPS_VEL"]
    samples = _gps_run(1)
    north = [(pos.decode(f[0][1])[0] - LAT) * M_PER_DEG for f in samples]
    alt = [vel.decode(f[1][1])[0] - 3000.0 for f in samples]
    p = GpsParams()
    assert _diff_std(north) == pytest.approx(p.noise_h_m, rel=0.1)
    assert _diff_std(alt) == pytest.approx(p.noise_v_m / 0.3048, rel=0.1)
    gs = [vel.decode(f[1][1])[1] for f in samples]
    true_gs = math.hypot(100, 150) * 0.3048 / 0.514444
    assert statistics.fmean(gs) == pytest.approx(true_gs, abs=0.05)
    assert statistics.pstdev(gs) == pytest.approx(p.noise_vel_mps / 0.514444, rel=0.15)
    fix, sats, cnt = zip(*[vel.decode(f[1][1])[3:] for f in samples[:3]])
    assert fix == (3, 3, 3) and cnt == (1, 2, 3)


@pytest.mark.parametrize("mode,fix", [("sbas", 4), ("gbas", 5)])
def test_augmented_gps(mode, fix):
    """SBAS- and GBAS-grade receivers: their own errors, and GPS_FIX says which."""
    from imaworld.config import GPS_AUGMENTATION

    pos, vel = MESSAGES["GPS_POS"], MESSAGES["GPS_VEL"]
    g = Gps(GpsParams(), 1, mode)
    samples = [g.sample(LAT, LON, 3000.0, 100.0, 150.0) for _ in range(3000)]
    north = [(pos.decode(f[0][1])[0] - LAT) * M_PER_DEG for f in samples]
    a = GPS_AUGMENTATION[mode]
    assert _diff_std(north) == pytest.approx(a["noise_h_m"], rel=0.15)
    assert statistics.pstdev(north) < 3 * (a["noise_h_m"] + a["bias_sigma_h_m"])
    assert {vel.decode(f[1][1])[3] for f in samples} == {fix}


def test_gauss_markov_statistics():
    gm = GaussMarkov(normal_stream(7, "t"), sigma=2.0, tau_s=10.0, dt_s=0.2)
    xs = [gm.step() for _ in range(200_000)]
    assert statistics.pstdev(xs) == pytest.approx(2.0, rel=0.1)
    lag1 = statistics.correlation(xs[:-1], xs[1:])
    assert lag1 == pytest.approx(math.exp(-0.02), abs=0.005)


def test_gps_lost_and_frozen():
    vel = MESSAGES["GPS_VEL"]
    g = Gps(GpsParams(), 3)
    first = g.sample(LAT, LON, 3000.0, 100.0, 0.0)
    g.state = "frozen"
    assert g.sample(LAT + 1, LON, 3100.0, 0.0, 100.0) == first  # data and counter repeat
    g.state = "lost"
    lost = g.sample(LAT, LON, 3000.0, 100.0, 0.0)
    assert vel.decode(lost[1][1])[3] == 0  # no fix
    s = Gps(GpsParams(lost_mode="silent"), 3)
    s.state = "lost"
    assert s.sample(LAT, LON, 3000.0, 100.0, 0.0) == []


def test_ahrs_noise():
    att, rate, acc = MESSAGES["AHRS_ATT"], MESSAGES["AHRS_RATE"], MESSAGES["AHRS_ACCEL"]
    a = Ahrs(AhrsParams(), 5)
    out = [a.sample(10.0, 2.0, 359.9, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0) for _ in range(5000)]
    p = AhrsParams()
    roll = [att.decode(f[0][1])[0] for f in out]
    hdg = [att.decode(f[0][1])[2] for f in out]
    hdg = [h - 360 if h > 180 else h for h in hdg]  # around north
    pr = [rate.decode(f[1][1])[0] for f in out]
    az = [acc.decode(f[2][1])[2] for f in out]
    assert _diff_std(roll) == pytest.approx(p.noise_att_deg, rel=0.15)
    assert _diff_std(hdg) == pytest.approx(p.noise_hdg_deg, rel=0.1)
    assert _diff_std(pr) == pytest.approx(p.noise_rate_dps, rel=0.2)  # 0.01 deg/s resolution
    assert _diff_std(az) == pytest.approx(p.noise_accel_g, rel=0.1)
    assert statistics.fmean(roll) == pytest.approx(10.0, abs=0.5)
    assert statistics.fmean(az) == pytest.approx(-1.0, abs=0.02)
    assert all(0 <= h < 360 for h in (att.decode(f[0][1])[2] for f in out))


def test_air_data_noise():
    m = MESSAGES["AIR_DATA"]
    a = AirData(AdcParams(), 9)
    out = [m.decode(a.sample(100.0, 3000.0, 0.0)[0][1]) for _ in range(5000)]
    p = AdcParams()
    ias, alt, vs = zip(*[(o[0], o[1], o[2]) for o in out])
    assert _diff_std(ias) == pytest.approx(p.noise_ias_kt, rel=0.1)
    assert _diff_std(alt) == pytest.approx(p.noise_alt_ft, rel=0.1)
    assert statistics.pstdev(vs) == pytest.approx(p.noise_vs_fpm, rel=0.1)
    assert statistics.fmean(ias) == pytest.approx(100.0, abs=1.5)
    assert [o[3] for o in out[:2]] == [1, 1] and [o[4] for o in out[14:17]] == [15, 0, 1]


def test_same_seed_same_errors_other_seed_other_errors():
    assert _gps_run(11, 50) == _gps_run(11, 50)
    assert _gps_run(11, 50) != _gps_run(12, 50)
    a1, a2 = Ahrs(AhrsParams(), 4), Ahrs(AhrsParams(), 4)
    args = (1.0, 2.0, 3.0, 0.1, 0.0, 0.0, 0.0, 0.0, -1.0)
    assert [a1.sample(*args) for _ in range(20)] == [a2.sample(*args) for _ in range(20)]
