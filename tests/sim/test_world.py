# SPDX-License-Identifier: Apache-2.0
"""The world with real JSBSim: trim, control signs, actuator fall-backs, C2 link, GPS faults,
crash, outputs, and byte-identical runs on the stand-in lockstep bus."""

from __future__ import annotations

import json

import pytest

from ima.canbus import proto
from ima.canbus.codec import BY_ID, MESSAGES

from conftest_helpers import NS, PILOTS, act_cmd_injector  # noqa: F401

START = {"lat_deg": 47.0, "lon_deg": 8.0, "altitude_ft": 3000, "airspeed_kt": 100,
         "heading_deg": 90}


def test_trim_matches_the_design():
    from imaworld import pilot
    from imaworld.config import DEFAULT
    from imaworld.fdm import Aircraft

    ac = Aircraft(DEFAULT, pilot.parse({"start": START}).start, 0, 500.0)
    trim = ac.trim()
    assert trim["thr"] == pytest.approx(0.71, abs=0.05)
    assert trim["pitch_trim"] == pytest.approx(0.19, abs=0.03)
    assert trim["elev"] == 0.0


def test_held_trim_stays_level(local_world):
    r = local_world("hold.yaml", 20, cmd="trim")
    truth = r.truth()
    assert len(truth) == 200 and truth[0]["t_ns"] == 0 and truth[-1]["t_ns"] == 19_900_000_000
    for rec in truth:
        assert rec["alt_ft"] == pytest.approx(3000, abs=30)
        assert abs(rec["roll_deg"]) < 3 and abs(rec["vs_fpm"]) < 200
        assert rec["heading_deg"] == pytest.approx(90, abs=3)
        assert rec["airspeed_kt"] == pytest.approx(100, abs=3)
    assert [e["state"] for e in r.events() if e["kind"] == "actuator_state"] == ["NORMAL"]
    s = r.summary()
    assert not s["crashed"] and s["steps"] == 2400 and s["frames_received"]["ACT_CMD_A"] == 400


@pytest.mark.parametrize("axis, value, check", [
    (1, 0.2, lambda t: t["roll_deg"] > 5),  # aileron + rolls right
    (2, 0.3, lambda t: t["heading_deg"] > 91),  # rudder + yaws right
    (0, 0.1, lambda t: t["pitch_deg"] < -3),  # elevator + pitches nose down
])
def test_control_signs(local_world, axis, value, check):
    def cmd(t, trim):
        c = list(trim)
        c[axis] += value if t < 2 * NS else 0
        return tuple(c)

    truth = local_world("hold.yaml", 2.5, cmd=cmd).truth()
    assert check(truth[-1]), truth[-1]


def test_actuators_hold_then_go_safe(local_world):
    r = local_world("hold.yaml", 6, cmd=lambda t, trim: trim if t < 3 * NS else None)
    ev = [(e["t_ns"], e["state"]) for e in r.events() if e["kind"] == "actuator_state"]
    assert [s for _, s in ev] == ["NORMAL", "HOLD_LAST", "SAFE"]
    # last command requested at 2.95 s: stale after 0.1 s, safe 0.5 s later
    assert 3.05e9 < ev[1][0] < 3.07e9 and 3.55e9 < ev[2][0] < 3.57e9
    t = r.truth()
    assert t[-1]["thr"] == 0 and t[-1]["elev"] == 0
    status = [MESSAGES["ACT_STATUS"].decode(d) for ts, i, d in r.bus.sent
              if i == MESSAGES["ACT_STATUS"].frame_id]
    assert len(status) == 120 and status[-1][4] == 2
    assert status[0][4] == 1 and status[1][4] == 0  # trim held until the first command


def test_sensor_frames_at_exact_multiples_of_their_period(local_world):
    r = local_world("hold.yaml", 2, cmd="trim")
    periods = {"GPS_POS": 200, "GPS_VEL": 200, "AHRS_ATT": 20, "AHRS_RATE": 20,
               "AHRS_ACCEL": 20, "AIR_DATA": 50, "ACT_STATUS": 50, "PILOT_MODE": 100,
               "PILOT_TARGETS": 100, "PILOT_STICK": 50}
    for name, ms in periods.items():
        ts = [t for t, i, _ in r.bus.sent if i == MESSAGES[name].frame_id]
        assert ts == [k * ms * 1_000_000 for k in range(2000 // ms)], name
    assert {BY_ID[i].name for _, i, _ in r.bus.sent} == set(periods)


def test_c2_link_and_downlink(local_world):
    st = MESSAGES["FCS_STATUS_A"]

    def downlink(t_from, t_until):  # FCS channel A reports AUTOPILOT at 20 Hz
        if t_from % 50_000_000:
            return []
        return [(t_from, st.frame_id, st.encode(2, 2, 0, 7, 0, 0, 0, 1, 90.0, 3000))]

    script = {"start": START, "events": [
        {"t": 0, "mode": "DIRECT"}, {"t": 1, "c2_link": "down"}, {"t": 3, "c2_link": "up"}]}
    r = local_world(script, 4, cmd="trim", extra_injector=downlink)
    up = [t for t, i, _ in r.bus.sent if i == MESSAGES["PILOT_STICK"].frame_id]
    assert not [t for t in up if 1 * NS <= t < 3 * NS]
    assert len(up) == 40  # 20 Hz for the 2 s the link was up
    truth = r.truth()
    assert truth[0]["fcs_mode"] is None and truth[5]["fcs_mode"] == "AUTOPILOT"
    assert truth[15]["c2_link"] == "down" and truth[35]["c2_link"] == "up"
    kinds = [(e["kind"], e.get("state")) for e in r.events()]
    assert ("c2_link", "down") in kinds and ("c2_link", "up") in kinds
    mode = [MESSAGES["PILOT_MODE"].decode(d) for t, i, d in r.bus.sent
            if i == MESSAGES["PILOT_MODE"].frame_id]
    assert mode[0][:3] == (1, 0, 0) and [m[3] for m in mode[:3]] == [1, 2, 3]


def test_gps_states_from_the_script(local_world):
    script = {"start": START, "events": [{"t": 1, "gps": "frozen"}, {"t": 2, "gps": "lost"},
                                         {"t": 3, "gps": "ok"}]}
    r = local_world(script, 4, cmd="trim")
    vel = MESSAGES["GPS_VEL"]
    frames = [(t, vel.decode(d)) for t, i, d in r.bus.sent if i == vel.frame_id]
    by_s = {t // 100_000_000: v for t, v in frames}
    assert by_s[12] == by_s[14] == by_s[18] == by_s[8]  # frozen from 1 s: the 0.8 s fix repeats
    assert by_s[22][3] == 0 and by_s[32][3] == 3
    assert [e["state"] for e in r.events() if e["kind"] == "sensor_state"] == \
        ["frozen", "lost", "ok"]


def test_crash_stops_the_bus(local_world):
    r = local_world("hold.yaml", 30, cmd=lambda t, trim: (trim[0], 1.0, 0.0, trim[3]))
    s = r.summary()
    assert s["crashed"] and s["reason"].startswith("roll") and 1 < s["crash_t_s"] < 20
    assert r.bus.stopped == proto.STOP_REQUESTED
    ev = r.events()
    assert [e["kind"] for e in ev[-2:]] == ["crash", "stop"]


def test_runs_are_byte_identical_for_a_seed(world_process):
    args = ["--seed", 42, "--turbulence", "light", "--wind", 15, "--wind-from", 300]
    inj = act_cmd_injector(lambda t: (0.0, 0.0332, 0.0038, 0.735))
    p1, d1, b1 = world_process(PILOTS / "c2_loss.yaml", 25, args, injector=inj)
    inj = act_cmd_injector(lambda t: (0.0, 0.0332, 0.0038, 0.735))
    p2, d2, b2 = world_process(PILOTS / "c2_loss.yaml", 25, args, injector=inj)
    assert p1.returncode == 0 and p2.returncode == 0, p1.stderr + p2.stderr
    for f in ("truth.jsonl", "world.jsonl", "world.json"):
        assert (d1 / f).read_bytes() == (d2 / f).read_bytes(), f
    assert [(e.end_ns, e.id, e.data) for e in b1.trace] == \
        [(e.end_ns, e.id, e.data) for e in b2.trace]
    t = [json.loads(x) for x in (d1 / "truth.jsonl").read_text().splitlines()]
    assert len(t) == 250 and t[-1]["wind_e_kt"] != 0  # wind + light turbulence act
    inj = act_cmd_injector(lambda t: (0.0, 0.0332, 0.0038, 0.735))
    p3, d3, _ = world_process(PILOTS / "c2_loss.yaml", 25, ["--seed", 43, *args[2:]],
                              injector=inj)
    assert (d3 / "truth.jsonl").read_bytes() != (d1 / "truth.jsonl").read_bytes()


def test_status_lines_and_nothing_else_on_stdout(world_process):
    p, d, _ = world_process(PILOTS / "hold.yaml", 3.0, ["--status"])
    assert p.returncode == 0, p.stderr
    lines = [json.loads(x) for x in p.stdout.splitlines()]
    assert [x["t_s"] for x in lines] == [0.0, 1.0, 2.0]
    assert set(lines[0]) == {"t_s", "alt_ft", "airspeed_kt", "heading_deg", "mode"}
    s = json.loads((d / "world.json").read_text())
    assert s["reason"] == "end of the run" and s["t_end_ns"] == 3 * NS


def test_wind_is_steady_from_the_start(local_world):
    r = local_world("hold.yaml", 10, cmd="trim", wind_kt=20, wind_from_deg=0)
    truth = r.truth()
    assert truth[0]["wind_n_kt"] == pytest.approx(-20) and truth[0]["wind_e_kt"] == 0
    for rec in (truth[0], truth[-1]):  # air-relative trim kept, drifting south of the heading
        assert rec["airspeed_kt"] == pytest.approx(100, abs=1)
        assert rec["heading_deg"] == pytest.approx(90, abs=1)
        assert rec["track_deg"] == pytest.approx(100.8, abs=1)
        assert rec["alt_ft"] == pytest.approx(3000, abs=20)
