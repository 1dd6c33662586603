# SPDX-License-Identifier: Apache-2.0
"""The planned path: the local frame, turn radii, Dubins paths against cases solved by hand,
racetracks, scans, arcs, the final and the vertical profile."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ima.mission import geometry, plan
from ima.mission.geometry import KT, dubins

from .conftest import MISSIONS


def _paths(doc):
    p = plan.parse(doc, "x.yaml")
    return p, geometry.leg_paths(p)


def test_the_local_frame():
    f = geometry.Frame(47.0, 8.0)
    n, e = f.to_local(47.01, 8.01)
    assert n == pytest.approx(0.01 * math.pi / 180 * geometry.R_EARTH_M)
    assert e == pytest.approx(n * math.cos(math.radians(47.0)))
    lat, lon = f.to_geo(n, e)
    assert (float(lat), float(lon)) == pytest.approx((47.01, 8.01), abs=1e-12)
    assert f.to_local([47.0, 47.0], [8.0, 7.99]).shape == (2, 2)


def test_airspeeds_and_turn_radii():
    assert geometry.tas_kt(100.0, 0.0) == 100.0
    assert geometry.tas_kt(100.0, 10000.0) == pytest.approx(116.4, abs=0.1)  # sigma 0.7385
    assert geometry.turn_radius_m(100.0, 25.0) == pytest.approx(578.7, abs=0.1)
    assert geometry.hold_bank_deg(100.0, 25.0) == pytest.approx(15.36, abs=0.01)
    assert geometry.hold_bank_deg(200.0, 25.0) == 25.0  # standard rate would need 28.8°
    # at standard rate a full circle takes 120 s
    v = 100.0 * KT
    r = geometry.turn_radius_m(100.0, geometry.hold_bank_deg(100.0, 25.0))
    assert 2 * math.pi * r / v == pytest.approx(120.0)


# (start, course, end, course, expected length in radii, words)
DUBINS_CASES = [
    ((0, 0), 90, (0, 5), 90, 5.0, {"LSL", "RSR"}),  # straight ahead
    ((0, 0), 90, (2, 0), 270, math.pi, {"LSL"}),  # a U-turn to the left: a half circle
    ((0, 0), 90, (-1, 1), 180, math.pi / 2, {"RSR"}),  # a quarter turn to the right
    # opposite courses 10 radii apart on one line: turn off by asin(0.2), cross, turn back
    ((0, 0), 90, (0, 10), 270, math.pi + 2 * math.asin(0.2) + math.sqrt(96), {"LSR", "RSL"}),
    # turned around on the spot: three arcs of 60°, 300° and 60°
    ((0, 0), 0, (0, 0), 180, 7 * math.pi / 3, {"RLR", "LRL"}),
]


@pytest.mark.parametrize(("start", "c0", "end", "c1", "radii", "words"), DUBINS_CASES)
def test_dubins_against_cases_solved_by_hand(start, c0, end, c1, radii, words):
    r = 600.0
    d = dubins(np.array(start) * r, c0, np.array(end) * r, c1, r)
    assert d.length_m == pytest.approx(radii * r, rel=1e-9)
    assert d.word in words


def test_dubins_paths_arrive_and_are_the_shortest_of_their_kind():
    rng = np.random.default_rng(1)
    r = 500.0
    for _ in range(300):
        p0, p1 = rng.uniform(-3000, 3000, 2), rng.uniform(-3000, 3000, 2)
        c0, c1 = rng.uniform(0, 360, 2)
        d = dubins(p0, c0, p1, c1, r)
        t = geometry._Trace(p0, c0)
        t.follow(d)
        assert np.hypot(*(t.p - p1)) < 1e-6 and abs(math.remainder(t.course_deg - c1, 360)) < 1e-6
        assert t.length == pytest.approx(d.length_m)
        assert d.length_m >= math.hypot(*(p1 - p0)) - 1e-9
        # never longer than turning to face the fix, flying to it and turning a full circle
        assert d.length_m <= 2 * math.pi * r + math.hypot(*(p1 - p0)) + 4 * r + 2 * math.pi * r


def test_racetrack(doc):
    doc["legs"][2].update(laps=2, leg_time_s=60)
    _, paths = _paths(doc)
    hold = paths[2]
    v = hold.tas_kt * KT
    r = geometry.turn_radius_m(hold.tas_kt, geometry.hold_bank_deg(hold.tas_kt, 25.0))
    assert hold.kind == "racetrack" and hold.laps == 2 and hold.radius_m == pytest.approx(r)
    assert hold.length_m == pytest.approx(2 * (2 * math.pi * r + 2 * 60 * v))
    assert len(hold.entry) == 0  # the TF ended over the fix
    # inbound 090 with right turns: south of the inbound line, which ends at the fix; each
    # turn bulges a radius beyond the end of its leg
    fix = paths[1].points[-1]
    rel = hold.points - fix
    assert np.allclose(hold.points[-1], fix)
    assert rel[:, 0].max() == pytest.approx(0, abs=1e-6)
    assert rel[:, 0].min() == pytest.approx(-2 * r)
    assert rel[:, 1].min() == pytest.approx(-60 * v - r) and rel[:, 1].max() == pytest.approx(r)
    assert hold.end_course_deg == 90.0
    assert hold.duration_s == pytest.approx(2 * (120.0 + 120.0))  # two turns, two legs, twice


def test_a_hold_to_an_altitude_circles_until_it_is_reached(doc):
    doc["legs"][2] = {"type": "HA", "fix": "B", "inbound_course_deg": 90, "turn": "left",
                      "leg_time_s": 30, "altitude_ft": 9000}
    _, paths = _paths(doc)
    ha = paths[2]
    circuit = ha.length_m / ha.laps
    need = 6000 / (800 / (ha.tas_kt * KT * 60))
    assert (ha.laps - 1) * circuit < need <= ha.laps * circuit
    assert ha.altitude_at(need) == pytest.approx(9000) and ha.altitude_at(0) == 3000
    assert (ha.points[:, 0] - paths[1].points[-1][0]).min() >= -1e-6  # left: north of it


def test_scan_passes(doc):
    doc["legs"][2] = {"type": "SCAN", "fix": "B", "direction_deg": 0, "length_m": 2500,
                      "spacing_m": 400, "passes": 4, "side": "right"}
    _, paths = _paths(doc)
    scan = paths[2]
    assert scan.kind == "scan" and len(scan.passes) == 4
    b = paths[1].points[-1]
    for k, p in enumerate(scan.passes):
        assert np.hypot(*(p[1] - p[0])) == pytest.approx(2500)
        assert p[:, 1] - b[1] == pytest.approx([400 * k] * 2)  # stepping east: to the right
        assert (p[1, 0] > p[0, 0]) == (k % 2 == 0)  # north, south, north, south
    assert np.allclose(scan.points[0], b) and np.allclose(scan.points[-1], scan.passes[-1][1])
    assert scan.end_course_deg == pytest.approx(180.0)
    # each turn from one pass to the next is the shortest one the bank limit allows
    r = geometry.turn_radius_m(scan.tas_kt, 25.0)
    turn = dubins(scan.passes[0][1], 0, scan.passes[1][0], 180, r).length_m
    assert scan.length_m == pytest.approx(4 * 2500 + 3 * turn)


def test_arcs():
    p = plan.load(MISSIONS / "demo.yaml")
    paths = geometry.leg_paths(p)
    rf = paths[3]
    assert rf.kind == "arc" and rf.type == "RF"
    assert np.hypot(*(rf.points - rf.center).T) == pytest.approx(1500, abs=0.1)
    assert rf.length_m == pytest.approx(1500 * math.pi / 2, rel=1e-4)
    assert rf.end_course_deg == pytest.approx(180.0, abs=0.01)
    assert np.allclose(rf.points[0], paths[2].points[-1]) and np.allclose(
        rf.points[-1], geometry.Frame(47, 8).to_local(47.0, 8.1648318))
    legs = geometry.leg_paths(plan.load(MISSIONS / "legs.yaml"))
    laps, timed = legs[11], legs[15]
    assert laps.length_m == pytest.approx(2 * math.pi * 800)
    assert np.allclose(laps.points[0], laps.points[-1])
    assert timed.length_m == pytest.approx(120 * timed.tas_kt * KT)
    assert np.hypot(*(timed.points - timed.center).T) == pytest.approx(900)
    # the orbit is joined on the radial from the previous leg's end
    start = timed.entry[-1]
    assert np.allclose(start, timed.points[0])
    assert np.hypot(*(start - timed.center)) == pytest.approx(900)


def test_the_final_and_the_vertical_profile():
    p = plan.load(MISSIONS / "demo.yaml")
    paths = geometry.leg_paths(p)
    final, faf = paths[8], paths[7]
    rw = p.runways["RWY27"]
    thr = geometry.Frame(47, 8).to_local(rw.lat_deg, rw.lon_deg)
    # the glide path meets 2000 ft 8724 m before the aim point: over the FAF
    assert np.hypot(*(final.points[0] - faf.points[-1])) < 1.0
    assert np.allclose(final.points[1], thr) and final.points[2] == pytest.approx(
        thr + [0, -1500])
    at_thr = final.altitude_at(np.hypot(*(thr - final.points[0])))
    assert at_thr == pytest.approx(500 + 300 * math.tan(math.radians(3)) / 0.3048)
    assert final.altitude_at(final.length_m) == 500
    prof = geometry.vertical_profile(p, paths)
    mission = [x for x in paths if x.procedure is None]
    assert prof.distance_m[-1] == pytest.approx(sum(x.total_m for x in mission))
    assert prof.altitude_ft[0] == 3000 and prof.altitude_ft[-1] == 500
    assert np.all(np.diff(prof.distance_m) >= 0)
    assert list(prof.leg_start_m) == [x.index for x in mission]
    # the FAF's TF (the base leg) is a geometric path: a straight line from 2500 to 2000 ft
    mid = faf.total_m / 2
    assert faf.altitude_at(mid) == pytest.approx(2250)
    # a constant-airspeed climb is at max_vs_fpm, then level
    tf1 = paths[1]
    climb_m = 500 / (800 / (tf1.tas_kt * KT * 60))
    assert tf1.altitude_at(climb_m) == pytest.approx(3500) and tf1.altitude_at(climb_m / 2) == \
        pytest.approx(3250)


@pytest.mark.parametrize("name", ["demo", "legs", "tf_square"])
def test_each_leg_begins_where_the_one_before_ends(name):
    paths = geometry.leg_paths(plan.load(MISSIONS / f"{name}.yaml"))
    mission = [x for x in paths if x.procedure is None]
    for prev, p in zip(mission, mission[1:], strict=False):
        if p.type == "CF":  # a course line, intercepted from where the aircraft is
            continue
        first = p.entry[0] if len(p.entry) else p.points[0]
        # an orbit ends where it was joined, which its path cannot know: the next leg starts
        # from its fix (its centre), as the mission manager flies it
        end = prev.center if prev.type == "ORBIT" else prev.points[-1]
        assert np.hypot(*(first - end)) < 1.0, p.label


def test_tf_square_and_the_distance_to_a_leg():
    paths = geometry.leg_paths(plan.load(MISSIONS / "tf_square.yaml"))
    assert [p.length_m for p in paths[1:]] == pytest.approx([4000] * 4, abs=0.01)
    assert [p.end_course_deg for p in paths[1:]] == pytest.approx([90, 180, 270, 0], abs=1e-3)
    east = paths[1]
    assert east.distance_to([[100.0, 2000.0], [0.0, 5000.0], [-30.0, 0.0]]) == pytest.approx(
        [100.0, 1000.0, 30.0], abs=0.01)


def test_a_procedure_starts_from_where_it_is():
    paths = geometry.leg_paths(plan.load(MISSIONS / "legs.yaml"))
    direct, va = paths[18], paths[20]
    assert direct.procedure == "c2_loss" and direct.length_m == 0 and len(direct.points) == 1
    assert va.procedure == "autopilot_disengage" and len(va.points) == 0
    assert va.length_m == pytest.approx(geometry.OPEN_LEG_M * 4064 / 3000, rel=0.01)
