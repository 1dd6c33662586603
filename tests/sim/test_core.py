# SPDX-License-Identifier: Apache-2.0
"""The world's C++ (sim/core, imaworld.core): built and used, and the same flights to the byte
as the world's Python (--test-switch python-only), through what sends the work back to the
Python: actuator targets that change (commands, stale commands, hold and safe, votes), faults
that drive an actuator or act on the AHRS, steps near the ground and crashes."""

from __future__ import annotations

import math
import sys

import pytest
from conftest_helpers import NS

from ima.canbus.codec import MESSAGES
from imaworld import core
from imaworld.faultspec import parse

START = {"lat_deg": 47.0, "lon_deg": 8.0, "altitude_ft": 3000, "airspeed_kt": 100,
         "heading_deg": 90}
LOW = {**START, "altitude_ft": 650}  # 150 ft above the default terrain


def both(local_world, *args, **kw):
    """The same flight with the C++ steps and with the Python's: (c++ run, python run)."""
    c = local_world(*args, **kw)
    p = local_world(*args, test_switches=("python-only",), **kw)
    return c, p


def assert_same(c, p):
    assert c.world._stepper is not None and p.world._stepper is None
    assert c.world.ahrs.core is not None and p.world.ahrs.core is None
    assert c.world._truth_core is not None and p.world._truth_core is None
    assert c.world.adc.core is not None and p.world.adc.core is None
    for name in ("truth.jsonl", "world.jsonl"):
        assert (c.run_dir / name).read_bytes() == (p.run_dir / name).read_bytes(), name
    sc, sp = c.summary(), p.summary()
    sp.pop("test_switches")
    assert sc == sp
    assert c.bus.sent == p.bus.sent


def test_the_module_is_built_and_loads():
    assert core.module_path().is_file()
    assert core.load() is not None, core.why_not()


def test_commands_that_stop_hold_then_go_safe(local_world):
    def cmd(t, trim):
        if t >= 3 * NS:
            return None
        return (trim[0] + 0.05 * math.sin(t / NS * 4),) + trim[1:]

    c, p = both(local_world, "hold.yaml", 5, cmd=cmd)
    assert_same(c, p)
    states = [e["state"] for e in c.events() if e["kind"] == "actuator_state"]
    assert states == ["NORMAL", "HOLD_LAST", "SAFE"]


def test_no_command_at_all_holds_the_trim_then_goes_safe(local_world):
    c, p = both(local_world, "hold.yaml", 4)
    assert_same(c, p)
    states = [e["state"] for e in c.events() if e["kind"] == "actuator_state"]
    assert states == ["SAFE"], states


def test_simplex_fails_over_to_the_next_channel(local_world):
    def channel_cmd(ch, t, trim):
        if ch == 0 and t >= 1 * NS:
            return None  # A falls silent at 1 s, B goes on
        return (trim[0] + 0.01 * ch,) + trim[1:] if ch < 2 else None

    c, p = both(local_world, "hold.yaml", 3, channel_cmd=channel_cmd)
    assert_same(c, p)
    got = [(e["state"], e["channel"]) for e in c.events() if e["kind"] == "actuator_state"]
    assert got == [("NORMAL", "A"), ("NORMAL", "B")], got


def test_voted_channels_that_all_stop_hold_then_latch_safe(local_world):
    def channel_cmd(ch, t, trim):
        return None if t >= 1 * NS else trim

    c, p = both(local_world, "hold.yaml", 3, channel_cmd=channel_cmd, channels=3)
    assert_same(c, p)
    states = [e["state"] for e in c.events() if e["kind"] == "actuator_state"]
    assert states[-2:] == ["HOLD_LAST", "SAFE"], states


def test_voted_channels_one_voted_out(local_world):
    def channel_cmd(ch, t, trim):
        if ch == 2 and t >= 1 * NS:
            return (trim[0] + 0.4,) + trim[1:]  # C disagrees from 1 s on
        return (trim[0] + 0.02 * math.sin(t / NS * 3),) + trim[1:]

    c, p = both(local_world, "hold.yaml", 3, channel_cmd=channel_cmd, channels=3)
    assert_same(c, p)
    assert [e["channel"] for e in c.events() if e["kind"] == "voted_out"] == ["C"]


def test_actuator_faults_step_in_python_and_back(local_world):
    specs = [parse("actuator_jam:fid=j,at=0.5s,period=1s,on=300ms,surface=elev"),
             parse("actuator_hardover:fid=h,at=2s,until=2.5s,surface=ail,value=0.5")]
    c, p = both(local_world, "hold.yaml", 3, cmd="trim", faults=specs)
    assert_same(c, p)
    assert c.world.act.until > 0  # the C++ stepped again after the last spell


def test_sensor_faults_with_the_cplusplus_samples(local_world):
    specs = [parse("ahrs_stuck:fid=s,at=0.5s,until=1s"),
             parse("ahrs_stuck:fid=t,at=1.5s,until=2s,counter=frozen"),
             parse("ahrs_bias:fid=b,at=1.2s,until=2.5s,axis=roll,value=5"),
             parse("pitot_blocked:fid=p,at=1s,until=2s")]
    c, p = both(local_world, "hold.yaml", 3, cmd="trim", faults=specs, seed=5)
    assert_same(c, p)
    # a stuck AHRS whose spells fall between samples, and two stuck ones at once: each holds
    # the values of the last frames sent
    specs = [parse("ahrs_stuck:fid=s,at=1s,period=30ms,on=25ms,counter=frozen"),
             parse("ahrs_stuck:fid=t,at=2.01s,until=2.2s"),
             parse("ahrs_stuck:fid=u,at=2.1s,until=2.3s")]
    c, p = both(local_world, "hold.yaml", 2.5, cmd="trim", faults=specs, seed=5)
    assert_same(c, p)


def test_the_station_in_the_truth(local_world):
    st = MESSAGES["FCS_STATUS_A"]

    def downlink(t_from, t_until):  # FCS channel A reports AUTOPILOT, then DIRECT
        if t_from % 50_000_000:
            return []
        mode = 2 if t_from < 2 * NS else 1
        return [(t_from, st.frame_id, st.encode(mode, 2, 0, 7, 0, 0, 0, 1, 90.0, 3000))]

    script = {"start": START, "events": [
        {"t": 0, "mode": "DIRECT"}, {"t": 1, "c2_link": "down"}, {"t": 1.5, "gps": "frozen"},
        {"t": 2.5, "c2_link": "up"}, {"t": 3, "gps": "lost"}]}
    c, p = both(local_world, script, 4, cmd="trim", extra_injector=downlink)
    assert_same(c, p)
    modes = {t["fcs_mode"] for t in c.truth()}
    assert {None, "AUTOPILOT", "DIRECT"} <= modes
    assert {t["gps"] for t in c.truth()} == {"ok", "frozen", "lost"}


def test_a_roll_crash(local_world):
    c, p = both(local_world, "hold.yaml", 20, cmd=lambda t, trim: (trim[0], 1.0, 0.0, trim[3]))
    assert_same(c, p)
    assert c.summary()["reason"].startswith("roll")


def test_a_dive_into_the_ground(local_world):
    c, p = both(local_world, {"start": LOW, "events": []}, 20,
                cmd=lambda t, trim: (0.3, trim[1], trim[2], trim[3]))
    assert_same(c, p)
    s = c.summary()
    assert s["crashed"], s["reason"]
    # the last second was flown near the ground: the steps there were judged in Python
    assert min(t["agl_ft"] for t in c.truth()[-10:]) < 15


def test_numbers_are_rounded_and_written_as_the_python_does():
    import json
    import random

    from imaworld.world import _r

    rnd = random.Random(7)
    xs = [0.0, -0.0, 1e-4, 1e-5, 2.675, 1.005, 0.125, 1e15, 1e16, -5e-8, 4.9999999e-8,
          math.inf, -math.inf, math.nan, 359.9995, -0.00004]
    xs += [rnd.uniform(-1, 1) * 10 ** rnd.randint(-12, 18) for _ in range(20000)]
    xs += [round(rnd.uniform(-400, 400), rnd.randint(0, 8)) + rnd.choice([5e-8, -5e-5, 5e-4])
           for _ in range(20000)]
    number = core.load().json_number
    for x in xs:
        for n in (1, 2, 3, 4, 7):
            assert number(x, n) == json.dumps(_r(x, n)), (x, n)


def test_a_module_that_refuses_leaves_the_world_to_its_python(local_world, monkeypatch,
                                                                capsys):
    import types

    real = core.load()

    def refuse(*a):
        raise TypeError("refused")

    broken = types.SimpleNamespace(Normals=real.Normals, Stepper=refuse, Ahrs=refuse, Adc=refuse,
                                   Truth=refuse)
    p = local_world("hold.yaml", 2, cmd="trim", test_switches=("python-only",))
    monkeypatch.setattr(core, "load", lambda: broken)
    monkeypatch.setattr(core, "_told", set())
    c = local_world("hold.yaml", 2, cmd="trim")
    assert c.world._stepper is None and c.world.ahrs.core is None
    assert "in Python (" in capsys.readouterr().err
    for name in ("truth.jsonl", "world.jsonl"):
        assert (c.run_dir / name).read_bytes() == (p.run_dir / name).read_bytes(), name
    assert c.bus.sent == p.bus.sent


def test_a_stepper_refuses_what_is_not_jsbsim(local_world):
    r = local_world("hold.yaml", 0.1, cmd="trim")
    mod, ac, act = core.load(), r.world.ac, r.world.act
    lib = sys.modules[type(ac.fdm).__module__].__file__
    args = [lib, ac.fdm, ac.ctl_node, ac.node["agl"], ac.node["phi"], ac.node["cas"],
            ac.node["nz"], act.lo, act.hi, act.moves(1 / 120), 120, 60.0, 160.0, 3.8, 15.0]
    mod.Stepper(*args)
    for i, bad in ((1, object()), (1, ac.node["agl"]), (3, ac.fdm), (3, 1.5),
                   (2, (ac.node["agl"],) * 3), (7, (0.0,) * 3)):
        with pytest.raises((TypeError, ValueError)):
            mod.Stepper(*args[:i], bad, *args[i + 1:])
    with pytest.raises(ImportError):
        mod.Stepper("/nonexistent/_jsbsim.so", *args[1:])
    with pytest.raises(RuntimeError):
        mod.Stepper.__new__(mod.Stepper).run(1, 0, [0.0] * 4, (0.0,) * 4, 0, False)


@pytest.mark.parametrize("seed", range(6))
def test_a_target_holds_until_the_instant_targeted_names(seed):
    """Actuators.targeted: at every instant before `until`, _target() gives the same target and
    records nothing (checked on a copy, instant by instant, over random command streams with
    failovers, gaps, hold-last and safe)."""
    import copy
    import random

    from imaworld.actuators import Actuators
    from imaworld.config import DEFAULT

    rnd = random.Random(seed)
    act = Actuators(DEFAULT.actuators, (0.0, 0.0, 0.0, 0.6))
    step = 1_000_000  # 1 ms
    t = 0
    while t < 3 * NS:
        if rnd.random() < 0.02:  # a command on a channel that is not silent now
            ch = rnd.choice((0, 0, 1, 2))
            if not (1 * NS <= t < 1.3 * NS and ch == 0) and not 2 * NS <= t < 2.8 * NS:
                act.command(ch, t, (rnd.uniform(-0.1, 0.1), 0.0, 0.0, 0.6))
        act.targeted(t)
        until = act.until
        assert until > t
        probe = copy.deepcopy(act)
        last = [until - 1] if until < t + 400 * step else []  # the last instant it holds
        for u in [*range(t + step, min(until, t + 400 * step), step), *last]:
            n = len(probe.transitions)
            assert probe._target(u) == act.target, (t, u, until)
            assert len(probe.transitions) == n, (t, u, until)
        t += rnd.choice((step, 7 * step))
