# SPDX-License-Identifier: Apache-2.0
"""Flight-control modes in the real loop: DIRECT follows the stick, losing the C2 link in
DIRECT falls back to AUTOPILOT holding the current state, stale MISSION targets fall back to
AUTOPILOT. Judged from the truth trace and from the FCS status frames on the bus."""

from __future__ import annotations

import pytest
from flight_helpers import PILOTS, mission_system


def _at(rows, t_s):
    return min(rows, key=lambda r: abs(r["t_ns"] / 1e9 - t_s))


def _status(f):
    """(t, mode, fallback, target heading, target altitude) of each FCS_STATUS_A frame."""
    return [(t, str(d["FCS_MODE_A"]), str(d["FCS_FALLBACK_A"]), d["FCS_TGT_HDG_A"],
             d["FCS_TGT_ALT_A"]) for t, d in f.can_frames("FCS_STATUS_A")]


@pytest.fixture(scope="module")
def direct(flights):
    return flights.fly("direct", duration_s=60, seed=3, turbulence="none",
                       pilot=PILOTS / "direct.yaml")


@pytest.fixture(scope="module")
def c2_loss(flights):
    return flights.fly("c2_loss", duration_s=120, seed=3, turbulence="none",
                       pilot=PILOTS / "c2_loss.yaml")


@pytest.fixture(scope="module")
def mission(flights, tmp_path_factory):
    system = mission_system(tmp_path_factory.mktemp("mission"), ["120", "3300", "95", "40"])
    return flights.fly("mission", duration_s=90, seed=3, turbulence="none",
                       pilot=PILOTS / "mission.yaml", system=system)


def test_direct_surfaces_follow_the_stick(direct):
    truth = direct.truth()
    assert {m for _, m, *_ in _status(direct)[2:]} == {"DIRECT"}
    # direct.yaml: roll 0.2 right 5-8 s, 0.2 left 15-18 s, pull 0.1 25-28 s, throttle 0.9 35-45 s
    assert _at(truth, 7)["ail"] == pytest.approx(0.2, abs=0.01)
    assert _at(truth, 17)["ail"] == pytest.approx(-0.2, abs=0.01)
    assert _at(truth, 27)["elev"] == pytest.approx(-0.1, abs=0.01)  # pull: trailing edge up
    assert _at(truth, 40)["thr"] == pytest.approx(0.9, abs=0.01)
    assert _at(truth, 50)["thr"] == pytest.approx(0.73, abs=0.01)
    # ... and the aircraft answers: rolls right, then left, pitches up
    assert _at(truth, 8)["roll_deg"] - _at(truth, 5.5)["roll_deg"] > 10
    assert _at(truth, 18)["roll_deg"] - _at(truth, 15.5)["roll_deg"] < -10
    assert _at(truth, 28)["pitch_deg"] - _at(truth, 25.5)["pitch_deg"] > 3
    # envelope protection bounds the bank even with the stick free in DIRECT
    assert max(abs(r["roll_deg"]) for r in truth) <= 50


def test_c2_loss_in_direct_holds_current_state(c2_loss):
    status = _status(c2_loss)
    # link lost at 20 s: within the pilot port's refresh (1 s) plus a frame, AUTOPILOT/C2_LOST
    lost = [s for s in status if s[0] >= 20]
    first = next(s for s in lost if s[1] == "AUTOPILOT")
    assert first[2] == "C2_LOST" and first[0] < 22.5, first
    assert all(s[1] == "AUTOPILOT" and s[2] == "C2_LOST" for s in status if 22.5 <= s[0] < 80)
    hdg, alt = first[3], first[4]
    truth = c2_loss.truth()
    at_loss = _at(truth, first[0])
    assert hdg == pytest.approx(at_loss["heading_deg"], abs=3)
    assert alt == pytest.approx(at_loss["alt_ft"], abs=30)
    held = c2_loss.truth_between(40, 80)
    assert all(abs(r["alt_ft"] - alt) < 20 for r in held)
    assert all(abs((r["heading_deg"] - hdg + 180) % 360 - 180) < 3 for r in held)
    assert all(abs(r["roll_deg"]) < 10 for r in held)
    # link back at 80 s: the pilot's DIRECT again
    assert any(s[1] == "DIRECT" for s in status if s[0] > 80)


def test_stale_mission_targets_fall_back_to_autopilot(mission):
    status = _status(mission)
    # the stand-in mission manager sends 120° / 3300 ft / 95 kt until 40 s, then falls silent
    assert all(s[1] == "MISSION" for s in status if 1 <= s[0] < 40)
    after = [s for s in status if s[0] >= 40]
    fb = next(s for s in after if s[1] != "MISSION")
    assert fb[1] == "AUTOPILOT" and fb[2] == "MISSION_STALE" and fb[0] < 42.5, fb
    truth = mission.truth()
    assert _at(truth, 35)["heading_deg"] == pytest.approx(120, abs=5)  # it flew the mission
    held = mission.truth_between(50, 90)
    assert all(abs((r["heading_deg"] - fb[3] + 180) % 360 - 180) < 3 for r in held)
    assert all(abs(r["alt_ft"] - fb[4]) < 30 for r in held)
    assert all(s[1] == "AUTOPILOT" for s in status if s[0] > 42.5)


@pytest.fixture(scope="module")
def gps_loss(flights):
    return flights.fly("gps_loss", duration_s=150, seed=5, turbulence="light",
                       pilot=PILOTS / "gps_loss.yaml")


def test_gps_frozen_then_lost_dead_reckoning_keeps_the_hold(gps_loss):
    nav = [(t, int(d["FCS_NAV_FLAGS_A"])) for t, d in gps_loss.can_frames("FCS_STATUS_A")]
    # bit0 GPS valid, bit3 dead reckoning (config/can/rpas.dbc)
    assert all(f & 0x1 and not f & 0x8 for t, f in nav if 5 < t < 30)
    assert all(f & 0x8 and not f & 0x1 for t, f in nav if 35 < t < 120)  # frozen is caught too
    assert all(f & 0x1 and not f & 0x8 for t, f in nav if 125 < t)
    held = gps_loss.truth_between(30, 150)
    assert all(abs(r["alt_ft"] - 3000) < 60 for r in held)
    assert all(abs((r["heading_deg"] - 90 + 180) % 360 - 180) < 12 for r in held)
    assert not gps_loss.summary["crashed"]
