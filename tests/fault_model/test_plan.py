# SPDX-License-Identifier: Apache-2.0
"""A run's faults against its system: targets checked, common-mode faults expanded to every
node, triggers after another fault resolved, and the words each injector gets."""

from __future__ import annotations

from pathlib import Path

import pytest

from faultinject import grammar
from faultinject.grammar import FaultSpecError
from faultinject.plan import compile_plan, resolve_after
from faultinject.resolve import resolve
from ima.deploy import load_system

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def triplex():
    return load_system(ROOT / "config" / "systems" / "rpas_triplex.yaml")


def plan_of(system, *specs, duration=100.0):
    faults = [grammar.parse(s, f"f{k}") for k, s in enumerate(specs, start=1)]
    return compile_plan(system, resolve_after(faults), duration)


def test_each_injector_gets_its_words(triplex) -> None:
    p = plan_of(triplex, "nav_fcs@node2:memory_violation@60~5",
                "nav_fcs.ACT_CMD_OUT@node3:corrupt_output@10~2/4",
                "node1:wrong_output@30:mode=hardover,value=-1", "node2:dds_delay@20:frames=3",
                "node3:can_bus_off@40", "world:gps_loss@50~30", "node2:node_crash@70",
                "node3:node_freeze@80", "node2:module_reset@65")
    assert p.ske["node2"] == [
        "--fault", "memory_violation:fid=f1,at=60000000000,until=65000000000,partition=nav_fcs",
        "--fault", "module_reset:fid=f9,at=65000000000"]
    # ~2/4: active 2 s in every 4 s, with no end
    assert p.ske["node3"] == [
        "--fault", "corrupt_output:fid=f2,at=10000000000,period=4000000000,on=2000000000,"
        "partition=nav_fcs,port=ACT_CMD_OUT"]
    # the class's defaults are filled in: the injectors have none of their own
    assert p.io == {"node1": ["--fault=wrong_output:fid=f3,at=30000000000,mode=hardover,axis=elev,"
                              "value=-1.0,period_osc=2s,seed=1"]}
    assert p.dds == {"node2": ["--fault", "dds_delay:fid=f4,at=20000000000,frames=3"]}
    assert p.bus == ["--fault", "can_bus_off:fid=f5,at=40000000000,client=node3/io"]
    assert p.world == ["--fault", "gps_loss:fid=f6,at=50000000000,until=80000000000"]
    assert p.kills == {"node2": 70.0} and p.hangs == {"node3": 80.0}


def test_a_common_mode_fault_is_one_injection_per_node(triplex) -> None:
    p = plan_of(triplex, "nav_fcs@*:numeric_error@60")
    assert [i.node for i in p.injections] == ["node1", "node2", "node3"]
    assert all(len(p.ske[n]) == 2 for n in ("node1", "node2", "node3"))


def test_after_resolves_from_the_fault_it_follows(triplex) -> None:
    p = plan_of(triplex, "node2:node_crash@10", "node3:node_crash@after=f1+2.5")
    assert p.kills == {"node2": 10.0, "node3": 12.5}


@pytest.mark.parametrize("spec, says", [
    ("nav_fcs@node9:memory_violation@1", "no node 'node9'"),
    ("fcs@node1:memory_violation@1", "no partition 'fcs'"),
    ("nav_fcs.GPS_IN@node1:stuck_output@1", "is a destination port"),
    ("nav_fcs.NOPE@node1:stuck_output@1", "has no port 'NOPE'"),
    ("io.dance@node1:deadline_miss@1", "has no process 'dance'"),
    ("nav_fcs.NAV_OUT@node1:queuing_flood@1", "is not a queuing port"),
    ("world:gps_loss@200", "after the end of the run"),
    ("node2:node_crash@10~5", "is permanent"),
])
def test_targets_and_times_are_checked(triplex, spec: str, says: str) -> None:
    with pytest.raises(FaultSpecError) as err:
        plan_of(triplex, spec)
    assert says in str(err.value)


def test_a_condition_is_resolved_by_a_run_up_to_it(tmp_path) -> None:
    """The resolver asks for runs with the faults resolved so far and reads the truth."""
    runs = []

    def run_once(resolved, until):
        runs.append([f.spec() for f in resolved])
        d = tmp_path / f"r{len(runs)}"
        d.mkdir()
        t_mode = 7_000_000_000 if len(runs) == 1 else 9_500_000_000
        (d / "truth.jsonl").write_text(
            '{"t_ns": 0, "fcs_mode": "AUTOPILOT"}\n'
            f'{{"t_ns": {t_mode}, "fcs_mode": "DIRECT"}}\n')
        assert until({"mode": "DIRECT"}) and not until({"mode": "AUTOPILOT"})
        return d

    faults = [grammar.parse("node1:node_crash@5", "f1"),
              grammar.parse("world:c2_loss@mode=DIRECT+1", "f2"),
              grammar.parse("node2:node_crash@after=f2+2", "f3")]
    out = resolve(faults, run_once, 100.0)
    assert [f.trigger.at_s for f in out] == [5.0, 8.0, 10.0]
    assert runs == [["node1:node_crash@5"]]  # the condition came in the run with f1


def test_a_condition_that_never_comes_is_an_error(tmp_path) -> None:
    def run_once(resolved, until):
        (tmp_path / "truth.jsonl").write_text('{"t_ns": 0, "fcs_mode": "AUTOPILOT"}\n')
        return tmp_path

    with pytest.raises(FaultSpecError, match="mode MISSION never came"):
        resolve([grammar.parse("world:c2_loss@mode=MISSION", "f1")], run_once, 60.0)
