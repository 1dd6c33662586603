# SPDX-License-Identifier: Apache-2.0
"""The triplex flies, loses replicas and keeps flying: judged on the world's truth trace, the
actuators' vote (world.jsonl), the nodes' traces and the recorded CAN bus."""

from __future__ import annotations

import json

import pytest
from flight_helpers import LIGHT_BOUNDS, within

from ima.flight.summary import read_jsonl

SEED = 3
MAF_S = 0.05


def dump(run) -> str:
    s = {k: v for k, v in run.summary.items() if k not in ("hm_event_list", "vote_changes")}
    return json.dumps(s, indent=1)[:6000]


def _flew(run, duration):
    assert not run.summary["crashed"], dump(run)
    assert run.summary["flown_s"] >= duration - 1, dump(run)


@pytest.fixture(scope="module")
def nominal(launches):
    return launches.launch("nominal", duration_s=600.0, seed=SEED)


@pytest.fixture(scope="module")
def kill_one(launches):
    return launches.launch("kill_one", duration_s=300.0, seed=SEED, kill=[("node2", 120.0)])


@pytest.fixture(scope="module")
def hang_one(launches):
    return launches.launch("hang_one", duration_s=200.0, seed=SEED, hang=[("node2", 120.0)])


@pytest.fixture(scope="module")
def wrong_output(launches):
    return launches.launch("wrong", duration_s=300.0, seed=SEED,
                           wrong_output=[("node3", "elev", 0.3, 100.0)])


@pytest.fixture(scope="module")
def kill_two(launches):
    return launches.launch("kill_two", duration_s=300.0, seed=SEED,
                           kill=[("node2", 60.0), ("node3", 90.0)])


def test_triplex_flies_the_autopilot_profile_within_the_single_node_bounds(nominal):
    _flew(nominal, 600)
    s = nominal.summary
    assert not within(s, LIGHT_BOUNDS), (within(s, LIGHT_BOUNDS), dump(nominal))
    assert s["bank_deg_max"] <= 30, dump(nominal)
    assert s["samples_judged"] > 2000
    # nobody voted out, three replicas voted all along, every node agrees on all three
    assert s["voted_out"] == [], dump(nominal)
    assert s["vote_status"] == "MID3", dump(nominal)
    assert s["membership"] == ["node1", "node2", "node3"] and s["membership_agreed"]
    assert s["hm_events"] == 0, s["hm_event_list"]
    assert s["monitor_reports"] == []
    # the same climb capture as the single node
    climb = nominal.truth_between(380, 600)
    assert max(r["alt_ft"] for r in climb) - 4000 < 100


def test_each_replica_commands_on_its_own_redundancy_channel(nominal):
    import cantools

    from launch_helpers import ROOT

    db = cantools.database.load_file(ROOT / "config" / "can" / "rpas.dbc")
    ids = {db.get_message_by_name(f"ACT_CMD_{c}").frame_id: c for c in "ABC"}
    senders: dict[str, set] = {}
    for rec in read_jsonl(nominal.run_dir / "can.jsonl"):
        if rec.get("kind") == "can_tx" and rec.get("id") in ids:
            senders.setdefault(ids[rec["id"]], set()).add(rec.get("from"))
        if rec["t_ns"] > 5e9:
            break
    assert senders == {"A": {"node1/io"}, "B": {"node2/io"}, "C": {"node3/io"}}, senders


def test_killed_node_is_voted_out_within_three_frames(kill_one):
    s = kill_one.summary
    _flew(kill_one, 300)
    assert not within(s, LIGHT_BOUNDS), (within(s, LIGHT_BOUNDS), dump(kill_one))
    out = s["voted_out"]
    assert [v["node"] for v in out] == ["node2"], dump(kill_one)
    assert 120.0 <= out[0]["t_s"] <= 120.0 + 3 * MAF_S, out
    assert out[0]["reason"] == "absent"
    assert s["vote_status"] == "AVG2", dump(kill_one)
    # the bus stopped node2 at 120 s; nothing of it is on the bus afterwards
    kills = kill_one.records("can.jsonl", "node_kill")
    assert len(kills) == 1 and kills[0]["killed_node"] == 2 and kills[0]["t_ns"] == 120_000_000_000
    assert not [r for r in kill_one.records("can.jsonl", "can_tx")
                if r.get("from", "").startswith("node2/") and r["start_ns"] >= 120_000_000_000]
    # membership: node1 and node3 both drop node2, at the same instant, and agree
    assert s["membership"] == ["node1", "node3"] and s["membership_agreed"], dump(kill_one)
    drops = [e for e in s["membership_events"] if "node2" not in e["members"]]
    assert {e["node"] for e in drops} == {"node1", "node3"}
    assert len({e["t_s"] for e in drops}) == 1 and 120.0 < drops[0]["t_s"] <= 120.2
    # the surviving replicas' monitors saw node2 go
    assert any(r["node"] == "node1" and "node2 voted out" in r["text"] for r in s["monitor_reports"])
    assert s["killed"] == [{"node": "node2", "t_s": 120.0}]


def test_hung_node_is_found_by_the_dds_deadline_and_flown_around_as_a_dead_one(hang_one,
                                                                              kill_one):
    s = hang_one.summary
    _flew(hang_one, 200)
    assert not within(s, LIGHT_BOUNDS), (within(s, LIGHT_BOUNDS), dump(hang_one))
    assert s["hung"] == [{"node": "node2", "t_s": 120.0}] and s["killed"] == []
    # the bus froze node2's SKE and io at 120 s: nothing of it on the bus afterwards
    (hang,) = hang_one.records("can.jsonl", "node_hang")
    assert hang["hung_node"] == 2 and hang["t_ns"] == 120_000_000_000
    assert sorted(hang["clients"]) == ["node2", "node2/io"]
    assert not [r for r in hang_one.records("can.jsonl", "can_tx")
                if r.get("from", "").startswith("node2/") and r["start_ns"] >= 120_000_000_000]
    out = s["voted_out"]
    assert [(v["node"], v["reason"]) for v in out] == [("node2", "absent")], dump(hang_one)
    assert 120.0 <= out[0]["t_s"] <= 120.0 + 3 * MAF_S, out
    assert s["membership"] == ["node1", "node3"] and s["membership_agreed"], dump(hang_one)
    # DDS: node2's agent lives on, its liveliness holds, but its health stops: the others
    # miss its NodeHealth deadline and, waiting for its inputs, latch it as hung
    for k in (1, 3):
        dds = hang_one.records(f"dds{k}.jsonl")
        assert any(r["kind"] == "dds_deadline_missed" and r["peer"] == "node2" for r in dds)
        lost = [r for r in dds if r["kind"] == "dds_peer_lost" and r["peer"] == "node2"]
        assert [(r["reason"], r["was_alive"]) for r in lost] == [("hung", True)], lost
    # the frozen processor is switched off at the end; nothing else failed
    codes = hang_one.result.returncodes
    assert codes["node2"] == -9 and codes["node2/dds"] == 0
    assert all(c == 0 for name, c in codes.items() if name != "node2"), codes
    # a node that hangs is flown around exactly as one that dies at the same instant
    a = [(r["t_ns"], r["alt_ft"], r["heading_deg"]) for r in kill_one.truth_between(0, 199)]
    b = [(r["t_ns"], r["alt_ft"], r["heading_deg"]) for r in hang_one.truth_between(0, 199)]
    assert len(a) == len(b) > 1900
    assert a == b


def test_replica_with_wrong_output_is_voted_out_and_nothing_else_changes(wrong_output, nominal):
    s = wrong_output.summary
    _flew(wrong_output, 300)
    assert not within(s, LIGHT_BOUNDS), (within(s, LIGHT_BOUNDS), dump(wrong_output))
    out = s["voted_out"]
    assert [(v["node"], v["reason"]) for v in out] == [("node3", "miscompare")], dump(wrong_output)
    assert 100.0 <= out[0]["t_s"] <= 100.0 + 4 * MAF_S, out
    # membership unchanged: node3 is alive, only its output is wrong
    assert s["membership"] == ["node1", "node2", "node3"], dump(wrong_output)
    # node3's own monitor reports the disagreement to its health monitor
    hm = [e for e in s["hm_event_list"] if e["node"] == "node3"]
    assert hm and hm[0]["error"] == "APPLICATION_ERROR" and hm[0]["partition"] == "io", s["hm_event_list"]
    assert not [e for e in s["hm_event_list"] if e["node"] != "node3"]
    # nothing else changes: the aircraft flies as in the same flight without the fault (the
    # median, then the average, of the two healthy replicas is what it flew before), to the
    # last bit, over the 300 s both flew
    a = [(r["t_ns"], r["alt_ft"], r["heading_deg"]) for r in nominal.truth_between(0, 299)]
    b = [(r["t_ns"], r["alt_ft"], r["heading_deg"]) for r in wrong_output.truth_between(0, 299)]
    assert len(a) == len(b) > 2900
    diverged = [x for x, y in zip(a, b) if x != y]
    assert not diverged, f"first divergence at {diverged[0][0] / 1e9:.2f} s"


def test_two_of_three_killed_flies_on_one(kill_two):
    s = kill_two.summary
    _flew(kill_two, 300)
    assert not within(s, LIGHT_BOUNDS), (within(s, LIGHT_BOUNDS), dump(kill_two))
    assert [(v["node"], v["reason"]) for v in s["voted_out"]] == [("node2", "absent"), ("node3", "absent")]
    assert s["vote_status"] == "SINGLE", dump(kill_two)
    assert s["membership"] == ["node1"], dump(kill_two)
    # still following the pilot: the 90° turn ordered at 200 s is flown on node1 alone
    end_turn = kill_two.truth_between(290, 300)
    assert all(abs(r["heading_deg"] - 180) < 5 for r in end_turn), end_turn[-1]


def test_flight_plot_marks_the_events_of_a_run_with_hm_events(wrong_output):
    """The plot takes the run's events (here node3 voted out), not its HM events."""
    from ima.launch.options import default_pilot
    from ima.launch import summary as launch_summary

    assert wrong_output.summary["hm_events"] > 0
    s = launch_summary.summarise(wrong_output.run_dir, default_pilot(), 300.0,
                                 wrong_output.result.nodes, {}, plot=True)
    assert s["plot"].endswith("flight.png") and (wrong_output.run_dir / "flight.png").stat().st_size
    assert s["hm_events"] == wrong_output.summary["hm_events"]
