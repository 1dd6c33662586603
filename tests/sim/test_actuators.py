# SPDX-License-Identifier: Apache-2.0
"""Smart actuators: rate and position limits, hold-last, safe position, channel selection."""

from __future__ import annotations

import pytest

from imaworld.actuators import HOLD_LAST, NORMAL, SAFE, Actuators
from imaworld.config import ActuatorParams

NS = 1_000_000_000
DT = 1 / 120
TRIM = (0.0, 0.03, 0.0, 0.73)


def run(act, t0_s, t1_s, cmds=None, channel=0, period_s=0.05):
    """Step the actuators at 120 Hz over [t0, t1); cmds(t) sends a command every period."""
    k0, k1 = round(t0_s * 120), round(t1_s * 120)
    every = round(period_s * 120 * 10)  # in tenths of a step, to stay exact
    for k in range(k0, k1):
        t = k * NS // 120
        if cmds is not None and (k * 10) % every < 10:
            c = cmds(t / NS)
            if c is not None:
                act.command(channel, t, c)
        act.step(t, DT)
    return act


def test_rate_limits():
    a = run(Actuators(ActuatorParams(), TRIM), 0, 0.25, lambda t: (1.0, -1.0, 0.5, 1.0))
    assert a.pos[0] == pytest.approx(0.5, abs=0.02)  # 2 /s for 0.25 s
    assert a.pos[1] == pytest.approx(0.03 - 0.5, abs=0.02)
    assert a.pos[2] == pytest.approx(0.5, abs=1e-9)  # reached
    assert a.pos[3] == pytest.approx(0.73 + 0.125, abs=0.01)  # 0.5 /s
    assert a.state == NORMAL and a.channel == "A"


def test_position_limits():
    a = run(Actuators(ActuatorParams(), TRIM), 0, 2, lambda t: (3.0, -3.0, 3.0, 2.0))
    assert a.pos == pytest.approx([1.0, -1.0, 1.0, 1.0])


def test_hold_last_then_safe_then_resume():
    p = ActuatorParams()
    a = Actuators(p, TRIM)
    cmd = (0.1, -0.2, 0.05, 0.6)
    run(a, 0, 1.0, lambda t: cmd)  # last command at 0.95 s
    assert a.state == NORMAL and a.pos == pytest.approx(list(cmd))
    run(a, 1.0, 1.04)
    assert a.state == NORMAL  # not stale before 0.1 s of silence
    run(a, 1.04, 1.5)
    assert a.state == HOLD_LAST and a.pos == pytest.approx(list(cmd))
    run(a, 1.5, 1.55)
    assert a.state == HOLD_LAST  # 0.95 + 0.1 + 0.5 = 1.55
    run(a, 1.55, 3.0)
    assert a.state == SAFE and a.pos == pytest.approx([0, 0, 0, p.safe_throttle])
    run(a, 3.0, 4.5, lambda t: cmd)
    assert a.state == NORMAL and a.pos == pytest.approx(list(cmd))
    states = [(round(t / NS, 3), s) for t, s, _ in a.transitions]
    assert states == [(0.0, "NORMAL"), (1.058, "HOLD_LAST"), (1.558, "SAFE"), (3.0, "NORMAL")]


def test_safe_throttle_is_configurable():
    a = run(Actuators(ActuatorParams(safe_throttle=0.3), TRIM), 0, 5)
    assert a.state == SAFE and a.pos[3] == pytest.approx(0.3)


def test_startup_holds_the_trim_until_the_first_command():
    p = ActuatorParams()
    a = run(Actuators(p, TRIM), 0, 1.9)
    assert a.state == HOLD_LAST and a.pos == pytest.approx(list(TRIM))
    run(a, 1.9, 2.1)
    assert a.state == SAFE


def test_lowest_live_channel_is_used():
    a = Actuators(ActuatorParams(), TRIM)
    run(a, 0, 0.5, lambda t: (0.2, 0, 0, 0.5), channel=1)
    assert a.channel == "B" and a.pos[0] == pytest.approx(0.2)
    for k in range(60, 120):  # A and B both alive: A wins
        t = k * NS // 120
        if k % 6 == 0:
            a.command(0, t, (-0.2, 0, 0, 0.5))
            a.command(1, t, (0.2, 0, 0, 0.5))
        a.step(t, DT)
    assert a.channel == "A" and a.pos[0] == pytest.approx(-0.2)
    run(a, 1.0, 1.5, lambda t: (0.3, 0, 0, 0.5), channel=1)  # A falls silent
    assert a.channel == "B" and a.pos[0] == pytest.approx(0.3)
    assert [c for _, _, c in a.transitions] == ["B", "A", "B"]
