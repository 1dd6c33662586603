# SPDX-License-Identifier: Apache-2.0
"""AUTOPILOT over the default 10-minute pilot script (hold, 90° turn, 1000 ft climb) with a
10 kt wind, judged from the world's truth trace: calm air and light turbulence."""

from __future__ import annotations

import pytest
from flight_helpers import LIGHT_BOUNDS, dump, within

DURATION = 600.0


@pytest.fixture(scope="module")
def calm(flights):
    return flights.fly("calm", duration_s=DURATION, seed=7, turbulence="none", wind_kt=10)


@pytest.fixture(scope="module")
def light(flights):
    return flights.fly("light", duration_s=DURATION, seed=7, turbulence="light", wind_kt=10)


def _flew_whole(f):
    assert all(rc == 0 for rc in f.returncodes.values()), f.returncodes
    assert not f.summary["crashed"], dump(f)
    assert f.summary["flown_s"] >= DURATION - 1, dump(f)
    assert f.summary["samples_judged"] > 2000, dump(f)  # 10 Hz over the hold segments


def test_calm_air_holds_altitude_speed_heading(calm):
    _flew_whole(calm)
    s = calm.summary
    assert s["alt_err_ft_max"] <= 20, dump(calm)
    assert s["airspeed_err_kt_max"] <= 3, dump(calm)
    assert s["heading_err_deg_max"] <= 3, dump(calm)


def test_light_turbulence_bounds(light):
    _flew_whole(light)
    s = light.summary
    assert not within(s, LIGHT_BOUNDS), (within(s, LIGHT_BOUNDS), dump(light))


@pytest.mark.parametrize("which", ["calm", "light"])
def test_captures_turn_and_climb(which, request):
    f = request.getfixturevalue(which)
    _flew_whole(f)
    assert f.summary["bank_deg_max"] <= 30, dump(f)
    # 90° right turn ordered at 200 s (090 -> 180): captured, without swinging far past.
    turn = f.truth_between(200, 380)
    past = max((r["heading_deg"] - 180.0 for r in turn if 90 < r["heading_deg"] < 270), default=0)
    assert past < 10, f"heading overshoot {past:.1f}°"
    end_turn = f.truth_between(370, 380)
    assert all(abs(r["heading_deg"] - 180) < 5 for r in end_turn), end_turn[-1]
    # 1000 ft climb ordered at 380 s (3000 -> 4000 ft): captured with < 100 ft overshoot.
    climb = f.truth_between(380, 600)
    assert max(r["alt_ft"] for r in climb) - 4000 < 100
    assert all(abs(r["alt_ft"] - 4000) < 60 for r in f.truth_between(580, 600))


def test_autopilot_mode_reported(calm):
    modes = [m["mode"] for m in calm.summary["mode_changes"]]
    assert modes and modes[-1] == "AUTOPILOT", calm.summary["mode_changes"]
    assert calm.summary["hm_events"] == 0, calm.summary["hm_event_list"]
