# SPDX-License-Identifier: Apache-2.0
"""The remote pilot model: it takes the stick when the downlink shows DIRECT and the script does
not fly it, holds heading and altitude from the telemetry alone (a stand-in flight control,
fake_fcs.py, flies its stick to the surfaces), leaves scripted sticks alone, can be switched
off, and is deterministic."""

from __future__ import annotations

import json

import pytest

from ima.canbus.codec import MESSAGES

from conftest_helpers import NS
from fake_fcs import fly_with_fake_fcs

START = {"lat_deg": 47.0, "lon_deg": 8.0, "altitude_ft": 3000, "airspeed_kt": 100,
         "heading_deg": 90}
AP = {"t": 0, "mode": "AUTOPILOT", "heading_deg": 90, "altitude_ft": 3000}
NAV_OK = 0x7  # GPS, AHRS, air data


def reverts_at(t_s, fallback=5, flags=NAV_OK):
    """The flight control reports AUTOPILOT, then DIRECT (SENSOR_LOST) from t_s on."""
    return lambda t: (1, fallback, flags) if t >= t_s * NS else (2, 0, flags)


def run(tmp_path, script, seconds, mode_of_t, **kw):
    d = tmp_path / f"r{len(list(tmp_path.iterdir()))}"
    w, bus = fly_with_fake_fcs(d, script, seconds, mode_of_t, **kw)
    truth = [json.loads(x) for x in (d / "truth.jsonl").read_text().splitlines()]
    events = [json.loads(x) for x in (d / "world.jsonl").read_text().splitlines()]
    return truth, [e for e in events if e["kind"] == "pilot_model"], bus, d


def between(truth, a, b):
    return [r for r in truth if a * NS <= r["t_ns"] < b * NS]


def sticks(bus):
    m = MESSAGES["PILOT_STICK"]
    return [(t, m.decode(d)) for t, i, d in bus.sent if i == m.frame_id]


def test_a_reversion_to_direct_is_flown_from_the_telemetry(tmp_path):
    script = {"start": START, "events": [AP, {"t": 40, "heading_deg": 120},
                                         {"t": 75, "altitude_ft": 3300}]}
    truth, ev, bus, _ = run(tmp_path, script, 130, reverts_at(5), seed=2)
    # the downlink shows DIRECT from the 5 s status (heard 5 ms later); 1 s to take over
    assert ev[0] == {"t_ns": 6_050_000_000, "node": "world", "src": "pilot",
                     "kind": "pilot_model", "state": "flying", "heading_deg": 90.0,
                     "altitude_ft": 3000.0}
    assert [(e["state"], e["t_ns"] // NS) for e in ev[1:]] == [("targets", 40), ("targets", 75)]
    hold = between(truth, 15, 40)
    assert all(abs(r["heading_deg"] - 90) < 5 for r in hold)
    assert all(abs(r["alt_ft"] - 3000) < 30 for r in hold)
    turned = between(truth, 65, 75)
    assert all(abs(r["heading_deg"] - 120) < 5 for r in turned)
    assert all(abs(r["alt_ft"] - 3300) < 40 for r in between(truth, 115, 130))
    flown = between(truth, 5, 130)
    assert max(abs(r["roll_deg"]) for r in flown) < 20
    assert all(85 < r["airspeed_kt"] < 115 and -5 < r["pitch_deg"] < 10 for r in flown)
    # the inputs are human-sized: never beyond its limits, not a bang-bang
    st = [v for t, v in sticks(bus) if t > 7 * NS]
    assert max(abs(v[1]) for v in st) <= 0.2 and max(abs(v[0]) for v in st) <= 0.2


def test_it_flies_the_telemetry_not_the_truth(tmp_path):
    # the downlinked altitude reads 150 ft low: the pilot climbs the aircraft 150 ft
    truth, ev, _, _ = run(tmp_path, {"start": START, "events": [AP]}, 70, reverts_at(2),
                          alt_error_ft=-150.0)
    assert all(abs(r["alt_ft"] - 3150) < 30 for r in between(truth, 55, 70))


def test_a_scripted_stick_is_the_scripts(tmp_path):
    script = {"start": START, "events": [{"t": 0, "mode": "DIRECT",
                                          "stick": {"pitch": 0.0, "roll": 0.05}}]}
    truth, ev, bus, _ = run(tmp_path, script, 10, lambda t: (1, 0, NAV_OK))
    assert ev == []
    assert {(v[0], v[1]) for _, v in sticks(bus)} == {(0.0, 0.05)}


def test_direct_without_a_stick_in_the_script_is_flown_by_the_model(tmp_path):
    script = {"start": START, "events": [{"t": 0, "mode": "DIRECT", "heading_deg": 100},
                                         {"t": 30, "stick": {"roll": 0.0}}]}
    truth, ev, _, _ = run(tmp_path, script, 40, lambda t: (1, 0, NAV_OK))
    # the script asked DIRECT: the pilot holds his own targets, until the script takes the stick
    assert [(e["state"], e.get("heading_deg")) for e in ev] == [("flying", 100.0), ("off", None)]
    assert ev[1]["t_ns"] == 30 * NS
    assert abs(between(truth, 25, 30)[-1]["heading_deg"] - 100) < 5


def test_it_lets_go_when_the_downlink_stops_showing_direct(tmp_path):
    def mode(t):
        if t >= 20 * NS:
            return None  # the link's downlink falls silent
        return (1, 5, NAV_OK) if t >= 2 * NS else (2, 0, NAV_OK)

    truth, ev, bus, _ = run(tmp_path, {"start": START, "events": [AP]}, 25, mode)
    assert [e["state"] for e in ev] == ["flying", "off"]
    assert 21 * NS <= ev[1]["t_ns"] <= 21_100_000_000  # the status is stale after 1 s
    assert {(v[0], v[1]) for t, v in sticks(bus) if t > 21_500_000_000} == {(0.0, 0.0)}


def test_switched_off_by_the_script(tmp_path):
    truth, ev, _, _ = run(tmp_path, {"start": START, "pilot_model": False, "events": [AP]}, 10,
                          reverts_at(1))
    assert ev == []


def test_deterministic(tmp_path):
    script = {"start": START, "events": [AP, {"t": 10, "heading_deg": 60}]}
    a = run(tmp_path, script, 25, reverts_at(2), seed=6, turbulence="light", wind_kt=10)
    b = run(tmp_path, script, 25, reverts_at(2), seed=6, turbulence="light", wind_kt=10)
    assert a[2].sent == b[2].sent
    for f in ("truth.jsonl", "world.jsonl", "world.json"):
        assert (a[3] / f).read_bytes() == (b[3] / f).read_bytes()
    assert json.loads((a[3] / "world.json").read_text())["pilot_model"][0]["state"] == "flying"


@pytest.mark.parametrize("flags, steady", [(0x6, (1,)), (0x2, (0, 1))])
def test_without_position_or_altitude_the_hands_stay_steady(tmp_path, flags, steady):
    # no position (neither GPS nor dead reckoning): no track to fly by, the roll input stays;
    # no altitude either (neither GPS nor air data): the pitch input stays too
    truth, ev, bus, _ = run(tmp_path, {"start": START, "events": [AP]}, 15,
                            reverts_at(1, flags=flags))
    st = [v for t, v in sticks(bus) if t > 3 * NS]
    for axis in steady:
        assert len({v[axis] for v in st}) == 1, axis
