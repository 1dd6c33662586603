# SPDX-License-Identifier: Apache-2.0
"""Each oracle can fail: a real run of the triplex in which a test-only switch plants the
violation the oracle exists to catch (an overrunning partition that eats the next window, an
HM action the tables do not prescribe, a non-target's port corrupted, a vote-out skipped), or
a catalogue entry that asks what the run did not do, judged against one golden run. The
oracle must report the violation, and name where it is."""

from __future__ import annotations

import dataclasses
import json
import shutil
import sys
from pathlib import Path

import pytest

from faultinject import catalogue, grammar, oracles
from faultinject.judge import judge
from ima.deploy import load_system
from ima.launch import judging
from ima.launch import run as launch_run
from ima.launch.options import LaunchOptions

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flight"))
from flight_helpers import fly_unless_host_stalled  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"
PILOT = ROOT / "sim" / "pilots" / "workload_autopilot.yaml"
DURATION = 12.0


def _opts(run_dir: Path, faults=(), switches=(), golden=None) -> LaunchOptions:
    return LaunchOptions(system=TRIPLEX, run_dir=run_dir, duration_s=DURATION, seed=3,
                         pilot=PILOT, faults=[grammar.parse(s, f"f{k}")
                                              for k, s in enumerate(faults, start=1)],
                         test_switches=list(switches), port_hashes=True, judge=False,
                         golden=golden, kind="test")


@pytest.fixture(scope="module")
def flights(tmp_path_factory):
    """Flies (once) the golden run and each run with a planted violation; judges them."""
    base = tmp_path_factory.mktemp("oracles")
    golden = base / "golden"
    fly_unless_host_stalled(lambda: judging.fly_golden(_opts(golden), golden), golden, "golden")
    system = load_system(TRIPLEX)
    cache = {}

    def fly(name: str, faults, switches=()) -> dict:
        if name not in cache:
            run_dir = base / name
            opts = _opts(run_dir, faults, switches, golden)
            result = launch_run.launch(opts)
            cache[name] = {"result": result, "system": system, "golden": golden,
                           "verdicts": judging.judge(opts, result, system)}
        return cache[name]
    return fly


def _brief(verdict: dict) -> str:
    return json.dumps(verdict)[:2000]


def test_temporal_isolation_fails_when_an_overrun_eats_the_next_window(flights):
    run = flights("eat", ["nav_fcs@node1:cpu_overrun@5~1"],
                  ["ske@node1:overrun-eats-next-window"])
    v = run["verdicts"]["oracles"]["temporal_isolation"]
    assert v["verdict"] == "fail", _brief(v)
    # the victim is another partition of node1: the one whose window came next
    victims = {(x["node"], x["partition"]) for x in v["violations"]}
    assert victims and all(n == "node1" and p != "nav_fcs" for n, p in victims), _brief(v)


def test_hm_action_fails_when_the_ske_applies_another_action(flights):
    run = flights("hm", ["nav_fcs@node2:memory_violation@5"],
                  ["ske@node2:hm-action=nav_fcs:IDLE"])
    v = run["verdicts"]["oracles"]["hm_action"]
    assert v["verdict"] == "fail", _brief(v)
    bad = v["violations"][0]
    assert bad["node"] == "node2" and bad["partition"] == "nav_fcs", _brief(v)
    assert bad["applied"] != [] and bad["applied"] not in bad["tables"], _brief(v)


def test_data_isolation_fails_when_a_non_target_port_is_corrupted(flights):
    run = flights("port", ["nav_fcs@node1:memory_violation@6"],
                  ["ske@node3:corrupt-port=io.GPS_OUT@3005ms"])
    v = run["verdicts"]["oracles"]["data_isolation"]
    assert v["verdict"] == "fail", _brief(v)
    # the switch flips the message in place, behind its writer's back: io's own writes hash
    # as in the golden run; what node3's nav_fcs made of the corrupted fix does not
    assert {(x["node"], x["partition"]) for x in v["violations"]} == {("node3", "nav_fcs")}, \
        _brief(v)
    assert all(3.0 <= x["t_s"] < 6.0 for x in v["violations"]), _brief(v)  # before the fault


def test_detection_fails_when_the_voter_skips_the_vote_out(flights):
    run = flights("novote", ["node2:wrong_output@5:mode=bias,axis=elev,value=0.4"],
                  ["world:no-vote-out"])
    f = run["verdicts"]["oracles"]["detection"]["faults"][0]
    assert "vote_out" not in f["fired_ms"], _brief(f)
    # the replica's own monitor still sees it, and the catalogue accepts either; a class that
    # wants the vote-out alone is not detected as it must be
    assert "self_monitor" in f["fired_ms"] and f["verdict"] == "pass", _brief(f)
    v = _rejudge(run, "wrong_output", detect={"redundant": ("vote_out",), "single": ("none",)})
    d = v["oracles"]["detection"]
    assert d["verdict"] == "fail" and d["faults"][0]["expected"] == ["vote_out"], _brief(d)


def _rejudge(run: dict, cls: str, **changes) -> dict:
    """The run judged again with the class's catalogue entry changed."""
    real = catalogue.load()
    patched = dict(real, **{cls: dataclasses.replace(real[cls], **changes)})
    saved = catalogue.load
    catalogue.load = lambda: patched
    try:
        r = run["result"]
        return judge(r.run_dir, run["golden"], r.plan, run["system"], DURATION)
    finally:
        catalogue.load = saved


def test_degraded_mode_fails_when_the_mode_is_not_reached(flights):
    run = flights("port", ["nav_fcs@node1:memory_violation@6"],
                  ["ske@node3:corrupt-port=io.GPS_OUT@3005ms"])
    v = _rejudge(run, "memory_violation", mode={"mode": "DIRECT", "fallback": "SENSOR_LOST"})
    d = v["oracles"]["degraded_mode"]
    assert d["verdict"] == "fail" and d["faults"][0]["reached_ms"] is None, _brief(d)


def test_confirmation_fails_without_the_evidence(flights):
    run = flights("eat", ["nav_fcs@node1:cpu_overrun@5~1"],
                  ["ske@node1:overrun-eats-next-window"])
    v = _rejudge(run, "cpu_overrun", evidence=("module_reset",))
    c = v["oracles"]["confirmation"]
    assert c["verdict"] == "fail" and "module_reset" in c["unconfirmed"][0], _brief(c)
    assert v["outcome"] == "not_activated"


def test_outcome_fails_when_the_catalogue_expects_another(flights):
    run = flights("novote", ["node2:wrong_output@5:mode=bias,axis=elev,value=0.4"],
                  ["world:no-vote-out"])
    v = _rejudge(run, "wrong_output", outcomes={"redundant": ("masked",), "single": ("masked",)})
    o = v["oracles"]["outcome"]
    assert o["verdict"] == "fail" and o["unexpected"] == ["f1"], _brief(o)


def test_envelope_fails_when_a_surface_goes_hard_over(flights):
    run = flights("hardover", ["world:actuator_hardover@5~5:surface=elev"])
    # the catalogue declares this a known limit: judged as declared, it is no violation
    assert run["verdicts"]["oracles"]["envelope"]["verdict"] == "pass"
    assert run["verdicts"]["oracles"]["envelope"]["left"], "the surface did not take it out"
    v = _rejudge(run, "actuator_hardover", known_limit=None)
    e = v["oracles"]["envelope"]
    assert e["verdict"] == "fail" and e["left"], _brief(e)


def test_envelope_fails_when_a_masked_fault_changes_the_truth(flights):
    run = flights("babble", ["node3:babbling_idiot@5~0.5"])
    assert run["verdicts"]["oracles"]["envelope"]["verdict"] == "pass"
    v = _rejudge(run, "babbling_idiot", masked="bit_identical", known_limit=None)
    e = v["oracles"]["envelope"]
    assert not e["truth_identical"] and e["verdict"] == "fail", _brief(e)
    assert "bit-identical" in e["why"], _brief(e)


def test_temporal_isolation_in_real_time_fails_beyond_its_tolerance(flights, tmp_path):
    """The real-time judgement (CPU time, window-start lateness), on copies of a run made to
    look like real-time ones: the partitions of a node that used five times the CPU time of
    their golden run, and windows that started 5 ms after their wall-clock time."""
    run = flights("eat", ["nav_fcs@node1:cpu_overrun@5~1"],
                  ["ske@node1:overrun-eats-next-window"])
    gold, bad = tmp_path / "golden", tmp_path / "run"
    shutil.copytree(run["golden"], gold)
    shutil.copytree(run["result"].run_dir, bad, ignore=shutil.ignore_patterns("golden"))
    for d in (gold, bad):
        launch = json.loads((d / "launch.json").read_text())
        (d / "launch.json").write_text(json.dumps(dict(launch, realtime=True)))
    stats = json.loads((bad / "node2.json").read_text())
    for p in stats["partitions"]:
        p["cpu_ns"] *= 5
    (bad / "node2.json").write_text(json.dumps(stats))
    for node in ("node3", "node1"):  # node1: the faulty module (its io is no target)
        lines = []
        for line in (bad / f"{node}.jsonl").read_text().splitlines():
            e = json.loads(line)
            if e.get("kind") == "window_start":
                e["wall_late_ns"] = 5_000_000
            lines.append(json.dumps(e))
        (bad / f"{node}.jsonl").write_text("\n".join(lines) + "\n")

    def judged(host_cpus):
        launch = json.loads((bad / "launch.json").read_text())
        (bad / "launch.json").write_text(json.dumps(dict(launch, host_cpus=host_cpus)))
        return judge(bad, gold, run["result"].plan, run["system"], DURATION)["oracles"][
            "temporal_isolation"]

    v = judged(8)  # a CPU for every module: lateness is a violation wherever it is
    assert v["time"] == "realtime" and v["verdict"] == "fail", _brief(v)
    why = {(m["node"], m["partition"]): m.get("why", "") for m in v["measured"]}
    assert "CPU time" in why[("node2", "nav_fcs")] and "CPU time" in why[("node2", "io")]
    assert "lateness" in why[("node3", "io")] and "lateness" in why[("node3", "nav_fcs")]
    assert "lateness" in why[("node1", "io")] and not v["known_limit"], _brief(v)
    assert oracles.REALTIME_TOLERANCE["late_p99_ms"] < 5.0
    # fewer CPUs than modules: the faulty module's lateness is the host's, a known limit;
    # another module's is still a violation
    v = judged(1)
    assert v["verdict"] == "fail", _brief(v)
    # every partition of node1 but the target: io, the flight data recorder, the mission
    # manager
    assert [(m["node"], m["partition"]) for m in v["known_limit"]] == [
        ("node1", "io"), ("node1", "fdr"), ("node1", "mission_manager")]
    assert {(m["node"], m["partition"]) for m in v["violations"]} >= {("node3", "io"),
                                                                      ("node3", "nav_fcs")}
    assert ("node1", "io") not in {(m["node"], m["partition"]) for m in v["violations"]}
