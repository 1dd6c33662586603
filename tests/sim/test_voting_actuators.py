# SPDX-License-Identifier: Apache-2.0
"""Voting smart actuators: the C voter over ACT_CMD_A/B/C, vote timing, channels voted out by
absence and by miscompare, 3 -> 2 -> 1 -> hold -> safe, the latched safe position, and what the
world writes about it (world.jsonl, world.json) and its command line."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import pytest

from conftest_helpers import ACT_CMDS as ACT
from conftest_helpers import NS, PILOTS, act_cmd_injector, model_voting

from imaworld.actuators import HOLD_LAST, NORMAL, SAFE, Actuators, VotingSelector
from imaworld.config import ActuatorParams

MS = 1_000_000
DT = 1 / 120
TRIM = (0.0, 0.03, 0.0, 0.73)
CMD = (0.05, -0.1, 0.02, 0.6)


def vote_times(t0_s: float, t1_s: float) -> list[int]:
    """The voting instants k * 50 ms + 45 ms in [t0, t1)."""
    return [k * 50 * MS + 45 * MS for k in range(200) if t0_s * NS <= k * 50 * MS + 45 * MS
            < t1_s * NS]


def drive(act: Actuators, t0_s: float, t1_s: float, cmds) -> Actuators:
    """Step at 120 Hz over [t0, t1); cmds(channel, t_s) -> command or None, sent every 50 ms
    (at k * 50 ms, arriving 0.2 ms later, as a frame on the wire would)."""
    k0, k1 = round(t0_s * 120), round(t1_s * 120)
    next_frame = -(-k0 * NS // 120 // (50 * MS)) * 50 * MS
    for k in range(k0, k1):
        t = k * NS // 120
        while next_frame <= t:
            for ch in range(3):
                c = cmds(ch, next_frame / NS)
                if c is not None:
                    act.command(ch, next_frame + 200_000, c)
            next_frame += 50 * MS
        act.step(t, DT)
    return act


def selector_args(**kw) -> dict:
    """VotingSelector's settings: the shipped model's voting, changed by kw."""
    v = model_voting()
    return {"thresholds": v.thresholds, "persist": v.persist, "offset_ns": round(v.offset_s * NS),
            "period_ns": round(v.period_s * NS), **kw}


def voting(n: int = 3, **kw) -> Actuators:
    p = ActuatorParams()
    return Actuators(p, TRIM, VotingSelector(n, **selector_args(**kw)))


def states(act: Actuators) -> list[tuple[float, str, str | None]]:
    return [(round(t / NS, 4), s, ch) for t, s, ch in act.transitions]


def ev(sel: VotingSelector, kind: str) -> list[tuple[float, dict]]:
    return [(round(t / NS, 4), f) for t, k, f in sel.events if k == kind]


# --- the selector alone ------------------------------------------------------------------------

def test_three_healthy_channels_vote_mid3_at_45_ms():
    a = drive(voting(), 0, 1, lambda ch, t: CMD)
    sel = a.selector
    assert a.state == NORMAL and a.channel == "ABC" and a.pos == pytest.approx(list(CMD))
    # Steps up to 0.9917 s: the votes of 0.045 .. 0.945 s.
    assert sel.votes == len(vote_times(0, 119 / 120)) == 19
    assert ev(sel, "vote") == [(0.045, {"status": "MID3", "used": ["A", "B", "C"]})]
    assert states(a) == [(0.05, "NORMAL", "ABC")]  # the first step after the first vote


def test_a_frame_counts_in_the_first_vote_at_or_after_its_end():
    sel = VotingSelector(3, **selector_args())
    sel.update(0, 45 * MS, CMD)  # ends exactly at the vote: in it
    sel.update(1, 45 * MS + 1, CMD)  # known before the vote, but ended after it: the next one
    sel.update(2, 44 * MS, CMD)
    assert sel.select(45 * MS, 0) == (CMD, "AC")
    assert sel.status == "AVG2"
    sel.update(0, 60 * MS, CMD)
    sel.update(2, 60 * MS, CMD)
    assert sel.select(94 * MS, 0) == (CMD, "AC")  # no vote yet: the last voted command
    assert sel.select(95 * MS, 0) == (CMD, "ABC")


def test_nothing_is_voted_before_the_first_command():
    a = drive(voting(), 0, 1.5, lambda ch, t: None)
    assert a.state == HOLD_LAST and a.pos == pytest.approx(list(TRIM))  # the startup rule
    assert a.selector.votes == 0 and a.selector.events == []
    # The nodes come up late: nobody is counted absent for the time before.
    drive(a, 1.5, 2.0, lambda ch, t: CMD)
    assert a.state == NORMAL and a.selector.voted_out == []
    assert a.selector.status == "MID3"


def test_a_channel_that_stops_is_voted_out_at_the_third_missed_vote():
    a = drive(voting(), 0, 2, lambda ch, t: None if ch == 1 and t >= 1.0 else CMD)
    sel = a.selector
    # Last frame of B at 0.95 s (in the 0.995 vote); misses at 1.045, 1.095, 1.145.
    assert ev(sel, "voted_out") == [(1.145, {"node": "node2", "channel": "B",
                                              "reason": "absent"})]
    assert ev(sel, "vote") == [(0.045, {"status": "MID3", "used": ["A", "B", "C"]}),
                               (1.045, {"status": "AVG2", "used": ["A", "C"]})]
    assert sel.voted_out == [{"t_ns": 1_145_000_000, "node": "node2", "channel": "B",
                              "reason": "absent"}]
    assert a.state == NORMAL and a.pos == pytest.approx(list(CMD))


def test_a_biased_channel_is_voted_out_and_the_output_is_the_healthy_median():
    healthy = {0: (0.05, -0.1, 0.02, 0.6), 2: (0.07, -0.1, 0.02, 0.6)}

    def cmds(ch, t):
        if ch == 1:
            return (0.06 + (0.3 if t >= 1.0 else 0.0), -0.1, 0.02, 0.6)
        return healthy[ch]

    a = voting()
    sel = a.selector
    seen = []
    for k in range(240):
        drive(a, k / 120, (k + 1) / 120, cmds)
        if sel.cmd is not None and (not seen or seen[-1][1] != sel.cmd):
            seen.append((sel.votes, sel.cmd, sel.status))
    # Before: the median is B (0.06); biased: C (0.07), the median of the healthy two and B;
    # once B is out, their average.
    assert [(s[1][0], s[2]) for s in seen] == [(0.06, "MID3"), (0.07, "MID3"),
                                               (pytest.approx(0.06), "AVG2")]
    assert ev(sel, "voted_out") == [(1.145, {"node": "node2", "channel": "B",
                                              "reason": "miscompare"})]
    assert sel.voter.reason(1) == "miscompare"


def test_three_two_one_then_hold_then_safe_latched():
    def cmds(ch, t):
        dead_at = (3.0, 2.0, 1.0)[ch]  # C at 1 s, B at 2 s, A at 3 s
        return None if t >= dead_at else CMD

    a = drive(voting(), 0, 6, cmds)
    sel = a.selector
    assert [(t, f["status"], "".join(f["used"])) for t, f in ev(sel, "vote")] == [
        (0.045, "MID3", "ABC"), (1.045, "AVG2", "AB"), (2.045, "SINGLE", "A"),
        (3.045, "SAFE", "")]
    assert [(t, f["channel"], f["reason"]) for t, f in ev(sel, "voted_out")] == [
        (1.145, "C", "absent"), (2.145, "B", "absent"), (3.145, "A", "absent")]
    # Hold the last voted command from the first vote without a candidate until
    # stale + hold (0.6 s) after the last vote with one (2.995 s), then safe.
    assert states(a) == [(0.05, "NORMAL", "ABC"), (1.05, "NORMAL", "AB"),
                         (2.05, "NORMAL", "A"), (3.05, "HOLD_LAST", None), (3.6, "SAFE", None)]
    assert a.pos == pytest.approx([0, 0, 0, 0])
    # Everybody back: the voter trusts nobody, the safe position stays.
    drive(a, 6, 7, lambda ch, t: CMD)
    assert a.state == SAFE and a.safe_latched and sel.status == "SAFE"


def test_the_safe_position_is_latched_even_if_channels_come_back_before_being_voted_out():
    a = drive(voting(persist=40), 0, 1, lambda ch, t: CMD)
    drive(a, 1, 2, lambda ch, t: None)  # 20 missed votes: nobody failed yet
    assert a.state == SAFE and a.selector.voted_out == []
    drive(a, 2, 3, lambda ch, t: CMD)
    assert a.selector.status == "MID3" and a.selector.cmd == CMD
    assert a.state == SAFE and a.pos == pytest.approx([0, 0, 0, 0])


def test_a_short_gap_of_every_channel_holds_and_resumes():
    a = drive(voting(), 0, 1, lambda ch, t: CMD)
    drive(a, 1, 1.1, lambda ch, t: None)  # two votes without anybody (1.045, 1.095)
    drive(a, 1.1, 2, lambda ch, t: CMD)
    assert [s for _, s, _ in a.transitions] == ["NORMAL", "HOLD_LAST", "NORMAL"]
    assert a.state == NORMAL and a.selector.voted_out == []
    assert [f["status"] for _, f in ev(a.selector, "vote")] == ["MID3", "SAFE", "MID3"]


def test_two_channels_that_disagree_go_safe():
    def cmds(ch, t):
        if ch == 2:
            return None  # C dead from the start
        return (0.3 * ch if t >= 1.0 else 0.0, 0, 0, 0.6)  # A and B 0.3 apart from 1 s

    a = drive(voting(), 0, 3, cmds)
    sel = a.selector
    assert [(t, f["status"]) for t, f in ev(sel, "vote")] == [
        (0.045, "AVG2"), (1.145, "DISAGREE")]  # disagreeing at 1.045, 1.095, 1.145
    assert [(t, f["channel"]) for t, f in ev(sel, "voted_out")] == [(0.145, "C")]
    assert sel.voter.disagree and sel.voter.failed == 0b100
    # The pair's average until the disagreement, then hold it, then safe, though A and B
    # still send.
    assert states(a)[-2:] == [(1.15, "HOLD_LAST", None), (1.7, "SAFE", None)]
    assert a.pos == pytest.approx([0, 0, 0, 0])


def test_thresholds_are_per_axis():
    def cmds(ch, t):
        return (0.0, 0.0, 0.15 if ch == 1 else 0.0, 0.6)  # B 0.15 off on the rudder

    loose = drive(voting(thresholds=(0.1, 0.1, 0.2, 0.1)), 0, 1, cmds)
    assert loose.selector.voted_out == []
    tight = drive(voting(thresholds=(0.1, 0.1, 0.1, 0.1)), 0, 1, cmds)
    assert [v["channel"] for v in tight.selector.voted_out] == ["B"]


def test_frames_of_channels_beyond_n_are_ignored():
    a = drive(voting(2), 0, 1, lambda ch, t: (0.5, 0, 0, 0.6) if ch == 2 else CMD)
    assert a.channel == "AB" and a.selector.status == "AVG2"
    assert a.pos == pytest.approx(list(CMD))


def test_a_vote_offset_outside_the_frame_is_refused():
    with pytest.raises(ValueError):
        VotingSelector(3, **selector_args(offset_ns=50 * MS))


# --- the world ---------------------------------------------------------------------------------

def fly3(local_world, seconds, cmd_of, **opts):
    """The hold script with ACT_CMD_A/B/C at 20 Hz: cmd_of(channel, t_ns, trim)."""
    return local_world("hold.yaml", seconds, channel_cmd=cmd_of, **opts)


def test_world_votes_and_a_failed_channel_changes_nothing_in_the_flight(local_world):
    healthy = fly3(local_world, 4, lambda ch, t, trim: trim, channels=3)

    def faulty(ch, t, trim):
        if ch == 1 and t >= 1 * NS:
            return (trim[0] + 0.3,) + trim[1:]  # B biased by 0.3 on the elevator
        if ch == 2 and t >= 2 * NS:
            return None  # C stops
        return trim

    r = fly3(local_world, 4, faulty, channels=3)
    # The median masks B, then the average of A and C, then A alone: bit for bit the trim.
    assert r.truth() == healthy.truth()
    evs = r.events()
    act = [e for e in evs if e["src"] == "actuators"]
    # The writer is the world; a voted_out event's node is the replica voted out.
    assert all(e["node"] == "world" for e in act if e["kind"] != "voted_out")
    votes = [(e["t_ns"], e["status"], e["used"]) for e in act if e["kind"] == "vote"]
    # The LoopbackBus delivers a frame sent at t at the end of its quantum (t + 5 ms).
    assert votes == [(45 * MS, "MID3", ["A", "B", "C"]), (1195 * MS, "AVG2", ["A", "C"]),
                     (2045 * MS, "SINGLE", ["A"])]
    out = [e for e in act if e["kind"] == "voted_out"]
    assert out == [
        {"t_ns": 1145 * MS, "node": "node2", "src": "actuators", "kind": "voted_out",
         "channel": "B", "reason": "miscompare"},
        {"t_ns": 2145 * MS, "node": "node3", "src": "actuators", "kind": "voted_out",
         "channel": "C", "reason": "absent"}]
    states = [(e["state"], e["channel"]) for e in act if e["kind"] == "actuator_state"]
    assert states == [("NORMAL", "ABC"), ("NORMAL", "AC"), ("NORMAL", "A")]
    s = r.summary()
    assert s["channels"] == 3
    v = s["vote"]
    assert v["status"] == "SINGLE" and v["used"] == ["A"] and not v["disagree"]
    assert [(x["channel"], x["reason"], x["t_ns"]) for x in v["voted_out"]] == [
        ("B", "miscompare", 1145 * MS), ("C", "absent", 2145 * MS)]
    assert v["persist"] == 3 and v["thresholds"] == [0.1] * 4 and v["offset_s"] == 0.045
    # Events are in time order.
    ts = [e["t_ns"] for e in evs if e["kind"] != "stop"]
    assert ts == sorted(ts)


def test_world_all_channels_dead_holds_then_goes_safe(local_world):
    r = fly3(local_world, 4, lambda ch, t, trim: trim if t < 1 * NS else None, channels=3,
             voting=dataclasses.replace(model_voting(), persist=2))
    act = [e for e in r.events() if e["src"] == "actuators"]
    assert [(e["kind"], e.get("status") or e.get("state") or e.get("channel"))
            for e in act] == [("vote", "MID3"), ("actuator_state", "NORMAL"),
                              ("vote", "SAFE"), ("actuator_state", "HOLD_LAST"),
                              ("voted_out", "A"), ("voted_out", "B"), ("voted_out", "C"),
                              ("actuator_state", "SAFE")]
    t_last = 995 * MS  # the frame of 0.95 s, delivered at 0.955 s
    hold, safe = [e["t_ns"] for e in act if e["kind"] == "actuator_state"][1:]
    assert hold == 1050 * MS and t_last + 600 * MS < safe <= t_last + 609 * MS
    assert {e["reason"] for e in act if e["kind"] == "voted_out"} == {"absent"}
    assert r.summary()["vote"]["status"] == "SAFE"
    assert r.truth()[-1]["elev"] == 0.0 and r.truth()[-1]["thr"] == 0.0


def test_world_not_told_the_channels_does_not_vote(local_world):
    r = local_world("hold.yaml", 1, cmd="trim")
    s = r.summary()
    assert s["channels"] == 1 and s["vote"] is None
    assert not [e for e in r.events() if e["kind"] in ("vote", "voted_out")]
    assert [e["channel"] for e in r.events() if e["kind"] == "actuator_state"] == ["A"]


def test_world_one_channel_is_voted_single(local_world):
    r = fly3(local_world, 3, lambda ch, t, trim: trim if ch == 0 and t < 1 * NS else None,
             channels=1)
    act = [(e["kind"], e.get("status") or e.get("state") or e.get("node"))
           for e in r.events() if e["src"] == "actuators"]
    assert act == [("vote", "SINGLE"), ("actuator_state", "NORMAL"), ("vote", "SAFE"),
                   ("actuator_state", "HOLD_LAST"), ("voted_out", "node1"),
                   ("actuator_state", "SAFE")]
    assert r.summary()["channels"] == 1 and r.summary()["vote"]["status"] == "SAFE"


def test_world_command_line_voting_options(world_process, tmp_path):
    def inj(a, b):
        return [f for ch in range(3) for f in act_cmd_injector(
            lambda t: (0.0, 0.03, 0.0, 0.73) if ch < 2 or t < NS // 2 else None, ACT[ch])(a, b)]

    p, run_dir, _ = world_process(PILOTS / "hold.yaml", 1.5, args=[
        "--channels", "3", "--vote-threshold", "0.1,0.2,0.3,0.05", "--vote-persist", "4",
        "--vote-offset", "0.03", "--vote-period", "0.05"], injector=inj)
    assert p.returncode == 0, p.stderr
    s = json.loads((run_dir / "world.json").read_text())
    v = s["vote"]
    assert s["channels"] == 3 and v["thresholds"] == [0.1, 0.2, 0.3, 0.05]
    assert v["persist"] == 4 and v["offset_s"] == 0.03
    # C's last frame (0.45 s, on the wire until ~0.45 s + 0.2 ms) is in the 0.48 s vote;
    # misses at 0.53, 0.58, 0.63, 0.68.
    assert v["voted_out"] == [{"t_ns": 680 * MS, "node": "node3", "channel": "C",
                               "reason": "absent"}]


@pytest.mark.parametrize("args, message", [
    (["--channels", "4"], "invalid choice"),
    (["--channels", "3", "--vote-threshold", "0.1,0.1,0.1"], "four numbers"),
    (["--channels", "3", "--vote-threshold", "0.1,0.1,nan,0.1"], "four numbers"),
    (["--channels", "3", "--vote-threshold", "0.1,-1,0.1,0.1"], "four numbers"),
    (["--channels", "3", "--vote-persist", "0"], "at least 1"),
    (["--channels", "2", "--vote-offset", "0.05", "--vote-period", "0.05"],
     "within the 0.05 s major frame"),
    (["--channels", "2", "--vote-period", "0"], "positive number"),
    (["--channels", "3", "--vote-threshold", "0.1,0.1,0.1,0.1"],
     "the vote needs --vote-persist, --vote-offset, --vote-period too"),
    (["--vote-persist", "2"], "only with --channels"),
])
def test_world_command_line_refuses_bad_voting_options(tmp_path, args, message):
    p = subprocess.run([sys.executable, "-m", "imaworld", "--bus", str(tmp_path / "none.sock"),
                        "--run-dir", str(tmp_path / "run"), "--pilot",
                        str(PILOTS / "hold.yaml"), *args],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and message in p.stderr, p.stderr


def test_world_test_switch_no_vote_out_never_votes_a_channel_out(local_world):
    """Test-only: with no-vote-out a biased replica stays in the vote (the median still masks
    it), so an oracle expecting it voted out must fail."""
    def faulty(ch, t, trim):
        return (trim[0] + 0.3,) + trim[1:] if ch == 1 and t >= 1 * NS else trim

    r = fly3(local_world, 3, faulty, channels=3, test_switches=("no-vote-out",))
    act = [e for e in r.events() if e["src"] == "actuators"]
    assert not [e for e in act if e["kind"] == "voted_out"]
    assert [(e["status"], e["used"]) for e in act if e["kind"] == "vote"] == [
        ("MID3", ["A", "B", "C"])]
    s = r.summary()
    assert s["vote"]["voted_out"] == [] and s["test_switches"] == ["no-vote-out"]
    assert r.world.act.selector.voter.failed == 0
    from imaworld.__main__ import build_parser

    assert build_parser().parse_args(["--bus", "b", "--run-dir", "r", "--pilot", "p",
                                      "--test-switch", "no-vote-out"]).test_switch == \
        ["no-vote-out"]
