# SPDX-License-Identifier: Apache-2.0
"""The world's fault injectors (--fault): each class's effect on the CAN frames the world sends
or on the aircraft's truth, its `fault` events, spells, the command line, and that faults that
never act change nothing."""

from __future__ import annotations

import json
import math

import pytest

from ima.canbus.codec import MESSAGES

from conftest_helpers import NS, PILOTS

from imaworld.__main__ import main as world_main
from imaworld.faultspec import parse
from imaworld.sensors import cas_from_impact, impact_pressure, static_pressure

MS = 1_000_000
START = {"lat_deg": 47.0, "lon_deg": 8.0, "altitude_ft": 3000, "airspeed_kt": 100,
         "heading_deg": 90}
AUTOPILOT = {"start": START, "events": [{"t": 0, "mode": "AUTOPILOT"}]}


def fly(local_world, seconds, *specs, script="hold.yaml", cmd="trim", **opts):
    return local_world(script, seconds, cmd=cmd, faults=[parse(s) for s in specs], **opts)


def frames(run, name):
    """(t_ns, decoded) of every frame `name` the world sent."""
    m = MESSAGES[name]
    return [(t, m.decode(d)) for t, i, d in run.bus.sent if i == m.frame_id]


def raw(run, name):
    m = MESSAGES[name]
    return [(t, d) for t, i, d in run.bus.sent if i == m.frame_id]


def faults(run):
    return [e for e in run.events() if e["kind"] == "fault"]


def in_spell(t, a_s, b_s):
    return a_s * NS <= t < b_s * NS


def test_gps_loss_reports_no_fix_for_its_spell(local_world):
    r = fly(local_world, 3, "gps_loss:fid=g1,at=1s,until=2s")
    vel = frames(r, "GPS_VEL")
    assert all((v[3], v[4]) == (0, 2) for t, v in vel if in_spell(t, 1, 2))
    assert all(v[3] == 3 for t, v in vel if not in_spell(t, 1, 2))
    cnt = [v[5] for _, v in vel]
    assert cnt == list(range(1, len(vel) + 1))  # the counter runs on through the loss
    assert faults(r) == [
        {"t_ns": 1 * NS, "node": "world", "src": "sensors", "kind": "fault", "fid": "g1",
         "class": "gps_loss", "target": "gps", "state": "applied", "detail": {}},
        {"t_ns": 2 * NS, "node": "world", "src": "sensors", "kind": "fault", "fid": "g1",
         "class": "gps_loss", "target": "gps", "state": "cleared", "detail": {}}]
    gps = {t["t_ns"] // (100 * MS): t["gps"] for t in r.truth()}
    assert (gps[5], gps[15], gps[25]) == ("ok", "lost", "ok")
    assert r.summary()["faults"] == [{"fid": "g1", "class": "gps_loss", "target": "gps",
                                      "duration": "transient",
                                      "spec": "gps_loss:fid=g1,at=1s,until=2s"}]


def test_gps_frozen_repeats_its_last_frames_counter_included(local_world):
    r = fly(local_world, 3, "gps_frozen:fid=g2,at=1100ms,until=2s")
    pos, vel = raw(r, "GPS_POS"), raw(r, "GPS_VEL")
    last = {"pos": [d for t, d in pos if t < 1100 * MS][-1],
            "vel": [d for t, d in vel if t < 1100 * MS][-1]}
    assert {d for t, d in pos if in_spell(t, 1.1, 2)} == {last["pos"]}
    assert {d for t, d in vel if in_spell(t, 1.1, 2)} == {last["vel"]}
    after = [MESSAGES["GPS_VEL"].decode(d)[5] for t, d in vel if t >= 2 * NS]
    assert after[0] == MESSAGES["GPS_VEL"].decode(last["vel"])[5] + 1


def test_gps_jump_moves_the_position_and_nothing_else(local_world):
    clean = fly(local_world, 2, seed=4)
    r = fly(local_world, 2, "gps_jump:fid=j,at=1s,north_m=100,east_m=-50", seed=4)
    a, b = frames(clean, "GPS_POS"), frames(r, "GPS_POS")
    for (t, p0), (_, p1) in zip(a, b):
        dn = (p1[0] - p0[0]) * math.pi / 180 * 6_378_137.0
        de = (p1[1] - p0[1]) * math.pi / 180 * 6_378_137.0 * math.cos(math.radians(47.0))
        want = (100.0, -50.0) if t >= NS else (0.0, 0.0)
        assert dn == pytest.approx(want[0], abs=0.05) and de == pytest.approx(want[1], abs=0.05)
    assert frames(clean, "GPS_VEL") == frames(r, "GPS_VEL")
    assert clean.truth() == r.truth()
    assert faults(r)[0]["detail"] == {"north_m": 100.0, "east_m": -50.0}


def test_ahrs_bias_adds_to_one_axis(local_world):
    clean = fly(local_world, 1, seed=5)
    r = fly(local_world, 1, "ahrs_bias:fid=b,at=0.5s,axis=roll,value=5",
            "ahrs_bias:fid=c,at=0.5s,axis=q,value=-2", seed=5)
    for (t, x0), (_, x1) in zip(frames(clean, "AHRS_ATT"), frames(r, "AHRS_ATT")):
        assert x1[0] - x0[0] == pytest.approx(5.0 if t >= NS // 2 else 0.0, abs=0.011)
        assert x1[1:] == x0[1:]
    for (t, x0), (_, x1) in zip(frames(clean, "AHRS_RATE"), frames(r, "AHRS_RATE")):
        assert x1[1] - x0[1] == pytest.approx(-2.0 if t >= NS // 2 else 0.0, abs=0.011)
        assert (x1[0], x1[2]) == (x0[0], x0[2])
    assert [(e["fid"], e["detail"]) for e in faults(r)] == [
        ("b", {"axis": "roll", "value": 5.0}), ("c", {"axis": "q", "value": -2.0})]


def test_ahrs_stuck_repeats_its_values_behind_a_running_counter(local_world):
    r = fly(local_world, 2, "ahrs_stuck:fid=s,at=1s")
    att = [(t, v) for t, v in frames(r, "AHRS_ATT")]
    before = [v for t, v in att if t < NS][-1]
    stuck = [v for t, v in att if t >= NS]
    assert {v[:4] for v in stuck} == {before[:4]}  # roll, pitch, heading, status
    cnt = [v[4] for t, v in att]
    assert cnt == [(k + 1) & 0xFF for k in range(len(att))]
    rates = {v[:3] for t, v in frames(r, "AHRS_RATE") if t >= NS}
    assert len(rates) == 1
    d = faults(r)[0]["detail"]
    assert d["counter"] == "run" and d["roll_deg"] == pytest.approx(before[0], abs=0.006)


def test_ahrs_stuck_with_a_frozen_counter_and_from_the_first_sample(local_world):
    r = fly(local_world, 1, "ahrs_stuck:fid=s,at=0,counter=frozen")
    att = raw(r, "AHRS_ATT")
    assert len({d for _, d in att}) == 1 and len(att) == 50
    assert MESSAGES["AHRS_ATT"].decode(att[0][1])[4] == 1


def test_pitot_blocked_ias_follows_altitude(local_world):
    # a gentle pull: the aircraft climbs while the trapped pitot pressure stays
    r = fly(local_world, 12, "pitot_blocked:fid=p,at=2s",
            cmd=lambda t, trim: (trim[0] - 0.06,) + trim[1:] if t >= 2 * NS else trim)
    air = frames(r, "AIR_DATA")
    truth = {t["t_ns"]: t for t in r.truth()}
    at = truth[2 * NS]
    ev = faults(r)[0]
    assert ev["detail"]["ias_kt"] == pytest.approx(at["airspeed_kt"], abs=0.01)
    end = truth[11_900 * MS]
    climbed = end["alt_ft"] - at["alt_ft"]
    assert climbed > 150
    # the model: total pressure trapped at 2 s, static from the pressure altitude now
    pt = static_pressure(at["alt_ft"]) + impact_pressure(at["airspeed_kt"])
    want = cas_from_impact(pt - static_pressure(end["alt_ft"]))
    ias = [v[0] for t, v in air if t == 11_900 * MS][0]
    assert ias == pytest.approx(want, abs=2.0)  # noise 0.3 kt, bias 0.3 kt, palt vs MSL
    assert ias > end["airspeed_kt"] + 15  # reads fast in a climb: the blocked pitot's sign
    assert [v[0] for t, v in air if t < 2 * NS][-1] == pytest.approx(at["airspeed_kt"], abs=2)


def test_c2_loss_stops_the_uplink_and_the_downlink(local_world):
    st = MESSAGES["FCS_STATUS_A"]

    def downlink(t_from, t_until):
        if t_from % (50 * MS):
            return []
        return [(t_from, st.frame_id, st.encode(2, 2, 0, 7, 0, 0, 0, 1, 90.0, 3000))]

    r = fly(local_world, 4, "c2_loss:fid=c,at=1s,until=2500ms", script=AUTOPILOT,
            extra_injector=downlink)
    for name in ("PILOT_MODE", "PILOT_TARGETS", "PILOT_STICK"):
        ts = [t for t, _ in raw(r, name)]
        assert ts and not [t for t in ts if in_spell(t, 1, 2.5)], name
        assert [t for t in ts if t >= 2500 * MS], name
    truth = {t["t_ns"] // (100 * MS): t for t in r.truth()}
    assert truth[12]["c2_link"] == "down" and truth[30]["c2_link"] == "up"
    assert r.summary()["frames_received"]["FCS_STATUS_A"] == 80  # received, not heard
    assert [(e["src"], e["target"], e["state"]) for e in faults(r)] == [
        ("station", "c2_link", "applied"), ("station", "c2_link", "cleared")]


def test_ap_disengage_commands_direct_over_the_uplink(local_world):
    r = fly(local_world, 3, "ap_disengage:fid=d,at=1s,until=2s", script=AUTOPILOT)
    modes = frames(r, "PILOT_MODE")
    assert {v[0] for t, v in modes if in_spell(t, 1, 2)} == {1}  # DIRECT
    assert {v[0] for t, v in modes if not in_spell(t, 1, 2)} == {2}  # the script's AUTOPILOT
    assert faults(r)[0]["target"] == "pilot_mode"


def test_actuator_jam_holds_the_surface_whatever_the_command(local_world):
    def cmd(t, trim):
        return (0.3 * math.sin(t / NS * 3),) + trim[1:]

    r = fly(local_world, 4, "actuator_jam:fid=a,at=1s,until=3s,surface=elev", cmd=cmd)
    elev = {t["t_ns"] // (100 * MS): t["elev"] for t in r.truth()}
    jammed = faults(r)[0]["detail"]["position"]
    assert {elev[k] for k in range(10, 30)} == {round(jammed, 4)}
    assert elev[35] != elev[29] and elev[5] != elev[9]
    assert [(e["src"], e["target"], e["class"], e["state"]) for e in faults(r)] == [
        ("actuators", "elev", "actuator_jam", "applied"),
        ("actuators", "elev", "actuator_jam", "cleared")]


def test_actuator_hardover_runs_to_its_stop_at_its_rate(local_world):
    r = fly(local_world, 3, "actuator_hardover:fid=h,at=1s,surface=ail,value=-0.5")
    ail = {t["t_ns"] // (100 * MS): t["ail"] for t in r.truth()}
    trim = ail[9]
    # 2 /s from the trimmed position: -1 reached (1 + trim) / 2 s later
    assert ail[12] == pytest.approx(trim - 0.4, abs=0.02)
    assert ail[20] == -1.0
    assert faults(r)[0]["detail"] == {"side": -1, "to": -1.0}


def test_actuator_float_drifts_to_neutral(local_world):
    r = fly(local_world, 4, "actuator_float:fid=f,at=1s,surface=thr,rate=0.5",
            "actuator_float:fid=g,at=1s,surface=rud")
    thr = {t["t_ns"] // (100 * MS): t["thr"] for t in r.truth()}
    assert thr[20] == pytest.approx(thr[10] - 0.5, abs=0.01)
    assert thr[30] == 0.0
    assert [e["detail"] for e in faults(r)] == [{"rate": 0.5}, {"rate": 0.1}]


def test_intermittent_spells_each_apply_and_clear(local_world):
    r = fly(local_world, 3, "actuator_jam:fid=i,at=0.5s,period=1s,on=200ms,surface=thr")
    got = [(e["t_ns"] / NS, e["state"], e["detail"]["spell"]) for e in faults(r)]
    assert got == [(0.5, "applied", 0), (0.7, "cleared", 0), (1.5, "applied", 1),
                   (1.7, "cleared", 1), (2.5, "applied", 2), (2.7, "cleared", 2)]
    ts = [e["t_ns"] for e in r.events() if e["kind"] != "stop"]
    assert ts == sorted(ts)


def test_faults_that_never_act_change_nothing(local_world):
    clean = fly(local_world, 2, seed=9, turbulence="light", wind_kt=10)
    r = fly(local_world, 2, "gps_loss:fid=late,at=1000s", "actuator_jam:fid=x,at=5s,"
            "surface=ail", seed=9, turbulence="light", wind_kt=10)
    assert clean.bus.sent == r.bus.sent
    assert (clean.run_dir / "truth.jsonl").read_bytes() == (r.run_dir / "truth.jsonl").read_bytes()
    assert (clean.run_dir / "world.jsonl").read_bytes() == (r.run_dir / "world.jsonl").read_bytes()
    a, b = clean.summary(), r.summary()
    assert "faults" not in a and [f["fid"] for f in b.pop("faults")] == ["late", "x"]
    assert a == b


@pytest.mark.parametrize("spec, says", [
    ("gps_los:fid=a,at=1s", "not a fault class of the world"),
    ("gps_loss:fid=a,at=1s,x=1", "unknown parameter 'x' (it takes no parameter)"),
    ("ahrs_bias:fid=a,at=1s,axis=yaw,value=1", "axis=yaw must be one of roll|pitch|hdg|p|q|r"),
    ("ahrs_bias:fid=a,at=1s,axis=roll", "value=NUMBER is required"),
    ("actuator_jam:fid=a,at=1s", "surface= must be one of elev|ail|rud|thr"),
    ("actuator_hardover:fid=a,at=1s,surface=rud,value=0", "not 0, is required"),
    ("actuator_float:fid=a,at=1s,surface=rud,rate=-1", "rate must be positive"),
    ("ahrs_stuck:fid=a,at=1s,counter=maybe", "counter=maybe must be run or frozen"),
    ("gps_jump:fid=a,at=1s", "give north_m=METRES and/or east_m=METRES"),
    ("gps_jump:fid=a,at=1s,north_m=far", "north_m=far is not a number"),
    ("c2_loss:fid=a,until=1s", "at=TIME is required"),
])
def test_bad_faults_are_refused_on_one_line(tmp_path, capsys, spec, says):
    rc = world_main(["--bus", str(tmp_path / "none.sock"), "--run-dir", str(tmp_path / "r"),
                     "--pilot", str(PILOTS / "hold.yaml"), "--fault", spec])
    err = capsys.readouterr().err
    assert rc == 2 and says in err and err.count("\n") == 1, err
    assert not (tmp_path / "r").exists()


def test_two_faults_with_one_fid_are_refused(tmp_path, capsys):
    rc = world_main(["--bus", str(tmp_path / "none.sock"), "--run-dir", str(tmp_path / "r"),
                     "--pilot", str(PILOTS / "hold.yaml"), "--fault", "c2_loss:fid=a,at=1s",
                     "--fault", "gps_loss:fid=a,at=2s"])
    assert rc == 2 and "fid=a is given to two faults" in capsys.readouterr().err


def test_the_process_takes_faults_on_its_command_line(world_process):
    p, run_dir, _ = world_process(PILOTS / "hold.yaml", 1.0, args=[
        "--fault", "gps_loss:fid=g,at=0.5s", "--fault", "actuator_jam:fid=j,at=0,surface=thr"])
    assert p.returncode == 0, p.stderr
    ev = [json.loads(x) for x in (run_dir / "world.jsonl").read_text().splitlines()]
    assert [(e["fid"], e["t_ns"]) for e in ev if e["kind"] == "fault"] == [("j", 0),
                                                                             ("g", NS // 2)]
