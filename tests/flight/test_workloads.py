# SPDX-License-Identifier: Apache-2.0
"""The campaign workloads of sim/pilots/workload_*.yaml in the real loop: each flies the modes
and transitions it is written for, as the downlink (FCS_STATUS_A on the bus) reports them."""

from __future__ import annotations

import pytest
from flight_helpers import PILOTS, dump, mission_system, status_frames, world_events


def _fly(flights, name, **kw):
    return flights.fly(f"workload_{name}", duration_s=60, seed=5, turbulence="none", wind_kt=10,
                       pilot=PILOTS / f"workload_{name}.yaml", **kw)


def _modes(f):
    """The (mode, fallback) changes on the downlink after INIT, with when they came."""
    out = []
    for t, m, fb, _ in status_frames(f):
        if m != "INIT" and (not out or out[-1][1:] != (m, fb)):
            out.append((round(t, 2), m, fb))
    return out


def _at(f, t_s):
    return min(f.truth(), key=lambda r: abs(r["t_ns"] / 1e9 - t_s))


def test_autopilot_workload(flights):
    f = _fly(flights, "autopilot")
    assert not f.summary["crashed"], dump(f)
    assert [m[1:] for m in _modes(f)][-1] == ("AUTOPILOT", "NONE")
    assert {m[1] for m in _modes(f)} == {"AUTOPILOT"}
    assert abs(_at(f, 28)["heading_deg"] - 120) < 3
    assert abs(_at(f, 59.9)["alt_ft"] - 3200) < 30


def test_direct_workload_is_flown_by_the_pilot_model(flights):
    f = _fly(flights, "direct")
    assert not f.summary["crashed"], dump(f)
    assert [m[1:] for m in _modes(f)][-1] == ("DIRECT", "NONE")
    pm = world_events(f, "pilot_model")
    assert [(e["state"], e["heading_deg"], e["altitude_ft"]) for e in pm] == [
        ("flying", 90.0, 3000.0), ("targets", 120.0, 3000.0), ("targets", 120.0, 3200.0)]
    assert abs(_at(f, 59.9)["heading_deg"] - 120) < 6
    assert _at(f, 59.9)["alt_ft"] > 3120
    assert max(abs(r["roll_deg"]) for r in f.truth()) < 20


def test_modes_workload_goes_through_every_transition(flights):
    f = _fly(flights, "modes")
    assert not f.summary["crashed"], dump(f)
    got = [(m, fb) for t, m, fb in _modes(f)]
    assert got == [("AUTOPILOT", "NONE"), ("DIRECT", "NONE"), ("AUTOPILOT", "NONE"),
                   ("DIRECT", "NONE"), ("AUTOPILOT", "C2_LOST"), ("DIRECT", "NONE")], _modes(f)
    times = [t for t, m, fb in _modes(f)][1:]
    for t, want in zip(times, (10, 25, 40, 45.5, 52)):  # C2: PILOT_IN stale after ~1 s
        assert want <= t < want + 1.6, (times, want)
    assert [e["state"] for e in world_events(f, "pilot_model")][::2] == ["flying", "off"]


@pytest.fixture(scope="module")
def mission(flights, tmp_path_factory):
    system = mission_system(tmp_path_factory.mktemp("workload_mission"),
                            ["120", "3300", "95", "40"])
    return _fly(flights, "mission", system=system)


def test_mission_workload(mission):
    f = mission
    assert not f.summary["crashed"], dump(f)
    got = [(m, fb) for t, m, fb in _modes(f)]
    assert got == [("MISSION", "NONE"), ("AUTOPILOT", "MISSION_STALE"), ("AUTOPILOT", "NONE")]
    stale, own = [t for t, m, fb in _modes(f)][1:]
    assert 40 <= stale < 41.5 and 50 <= own < 50.5
    assert abs(_at(f, 38)["heading_deg"] - 120) < 5
