# SPDX-License-Identifier: Apache-2.0
"""Degraded modes in the real loop (JSBSim world, CAN bus, one node): a stuck AHRS under the
autopilot hands the aircraft to the remote pilot (DIRECT, SENSOR_LOST), which the pilot model
flies from the downlink within a stated envelope, and the autopilot comes back when the AHRS
does; an autopilot disengagement from the station is flown the same way."""

from __future__ import annotations

import pytest
from flight_helpers import PILOTS, dump, fault, status_frames, world_events

# What the pilot model keeps in light turbulence with a 10 kt wind, flying from the telemetry
# alone (no attitude on the downlink): the envelope this test states.
ENVELOPE = {"bank_deg": 25.0, "pitch_deg": (-8.0, 12.0), "airspeed_kt": (80.0, 120.0),
            "alt_ft": 150.0, "heading_deg": 20.0}


def _within(rows, alt_ft, hdg_deg):
    e = ENVELOPE
    bad = []
    for r in rows:
        if abs(r["roll_deg"]) > e["bank_deg"]:
            bad.append(("bank", r["t_ns"], r["roll_deg"]))
        if not e["pitch_deg"][0] <= r["pitch_deg"] <= e["pitch_deg"][1]:
            bad.append(("pitch", r["t_ns"], r["pitch_deg"]))
        if not e["airspeed_kt"][0] <= r["airspeed_kt"] <= e["airspeed_kt"][1]:
            bad.append(("airspeed", r["t_ns"], r["airspeed_kt"]))
        if abs(r["alt_ft"] - alt_ft) > e["alt_ft"]:
            bad.append(("altitude", r["t_ns"], r["alt_ft"]))
        if abs((r["heading_deg"] - hdg_deg + 180) % 360 - 180) > e["heading_deg"]:
            bad.append(("heading", r["t_ns"], r["heading_deg"]))
    return bad[:5]


@pytest.fixture(scope="module")
def ahrs_stuck(flights):
    return flights.fly("ahrs_stuck", duration_s=90, seed=3, turbulence="light", wind_kt=10,
                       pilot=PILOTS / "hold.yaml", faults=[fault("world:ahrs_stuck@20~50", "ahrs1")])


@pytest.fixture(scope="module")
def disengage(flights):
    return flights.fly("disengage", duration_s=60, seed=4, turbulence="none", wind_kt=10,
                       pilot=PILOTS / "hold.yaml", faults=[fault("world:ap_disengage@10~35", "ap1")])


def test_a_stuck_ahrs_hands_the_aircraft_to_the_pilot_and_back(ahrs_stuck):
    f = ahrs_stuck
    assert all(rc == 0 for rc in f.returncodes.values()) and not f.summary["crashed"], dump(f)
    st = status_frames(f)
    assert {(m, fb) for t, m, fb, _ in st if 2 < t < 20} == {("AUTOPILOT", "NONE")}
    # stuck values are caught after 0.5 s (nav's ahrs_stuck_s), then the next frame reports
    first = next(s for s in st if s[0] >= 20 and s[1] != "AUTOPILOT")
    assert first[1:3] == ("DIRECT", "SENSOR_LOST") and first[0] < 20.7, first
    assert all(s[1:3] == ("DIRECT", "SENSOR_LOST") and not s[3] & 0x2 for s in st
               if first[0] <= s[0] < 70)
    # back at 70 s: the autopilot re-engages 2 s later (sensor_reengage_s)
    back = next(s for s in st if s[0] >= 70 and s[1] == "AUTOPILOT")
    assert back[2] == "NONE" and 72 <= back[0] < 72.2, back
    assert all(s[1:3] == ("AUTOPILOT", "NONE") for s in st if s[0] >= back[0])
    faults = world_events(f, "fault")
    assert [(e["fid"], e["state"], e["t_ns"]) for e in faults] == [
        ("ahrs1", "applied", 20 * 10**9), ("ahrs1", "cleared", 70 * 10**9)]
    pm = world_events(f, "pilot_model")
    assert [e["state"] for e in pm] == ["flying", "off"]
    assert pm[0]["heading_deg"] == 90.0 and pm[0]["altitude_ft"] == 3000.0
    assert 21 < pm[0]["t_ns"] / 1e9 < 22.2 and 72 < pm[1]["t_ns"] / 1e9 < 72.5
    # flown by the pilot model from the fault to the autopilot's return, and after it
    assert not _within(f.truth_between(20, 90), 3000.0, 90.0), _within(
        f.truth_between(20, 90), 3000.0, 90.0)


def test_an_autopilot_disengagement_is_flown_by_the_pilot_model(disengage):
    f = disengage
    assert not f.summary["crashed"], dump(f)
    st = status_frames(f)
    direct = [s for s in st if 10.5 <= s[0] < 45]
    assert direct and all(s[1:3] == ("DIRECT", "NONE") for s in direct)
    assert all(s[1] == "AUTOPILOT" for s in st if s[0] >= 45.5)
    req = {str(d["FCS_REQ_MODE_A"]) for t, d in f.can_frames("FCS_STATUS_A") if 11 < t < 45}
    assert req == {"DIRECT"}  # the station asked for it over the uplink
    assert [e["state"] for e in world_events(f, "pilot_model")] == ["flying", "off"]
    held = f.truth_between(15, 45)
    assert all(abs(r["alt_ft"] - 3000) < 40 and abs(r["heading_deg"] - 90) < 8 and
               abs(r["roll_deg"]) < 12 for r in held), _within(held, 3000.0, 90.0)
