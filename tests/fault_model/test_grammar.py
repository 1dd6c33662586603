# SPDX-License-Identifier: Apache-2.0
"""The fault's written forms: the short form and the YAML form give the same faults, every
class of the catalogue parses, and every mistake is refused with one line that names it."""

from __future__ import annotations

from pathlib import Path

import pytest

from faultinject import catalogue, grammar
from faultinject.grammar import FaultSpecError
from faultinject.model import Duration, Target, Trigger


def test_the_short_form() -> None:
    f = grammar.parse("nav_fcs@node2:memory_violation@60", "f1")
    assert f.cls == "memory_violation" and f.fid == "f1"
    assert f.target == Target("node2", "nav_fcs")
    assert f.trigger == Trigger(at_s=60.0) and f.duration == Duration()
    assert f.at_ns == 60_000_000_000 and f.until_ns is None
    assert f.spec() == "nav_fcs@node2:memory_violation@60"


@pytest.mark.parametrize("spec", [
    "node2:node_crash@120",
    "world:gps_loss@100~30",
    "node1:wrong_output@60:mode=random,axis=ail",
    "nav_fcs@*:numeric_error@60",
    "nav_fcs.ACT_CMD_OUT@node3:stuck_output@mode=AUTOPILOT+5",
    "world:c2_loss@10~2/10/60",
    "node2:can_drop@30~5:id=0x8d80641",
    "io.rx@node1:deadline_miss@12.5",
    "node3:dds_delay@after=f1+2~4:frames=3",
])
def test_every_form_gives_itself_back(spec: str) -> None:
    f = grammar.parse(spec, "f2")
    assert grammar.parse(f.spec(), "f2") == f


def test_durations() -> None:
    assert grammar.parse("world:c2_loss@10~5", "a").duration == Duration("transient", 5.0)
    f = grammar.parse("world:c2_loss@10~1/4/30", "a")
    assert f.duration == Duration("intermittent", length_s=30.0, on_s=1.0, period_s=4.0)
    assert f.until_ns == 40_000_000_000
    assert grammar.parse("world:c2_loss@10~1/4", "a").duration.length_s is None


@pytest.mark.parametrize("spec, says", [
    ("nav_fcs@node2", "expected WHERE:CLASS@WHEN"),
    ("nav_fcs@node2:memory_violation", "expected CLASS@WHEN"),
    ("nav_fcs@node2:melted@3", "unknown fault class 'melted'"),
    ("node2:memory_violation@3", "targets a partition: write PARTITION@NODE"),
    ("nav_fcs@node2:node_crash@3", "targets a node: write NODE:"),
    ("nav_fcs@node2:stuck_output@3", "targets a port: PARTITION.PORT@NODE"),
    ("node1:gps_loss@3", "acts on the world: write world:"),
    ("world:gps_loss@-3", "must be a finite number >= 0"),
    ("world:gps_loss@nan", "must be a finite number >= 0"),
    ("world:gps_loss@x", "is not a number of seconds"),
    ("world:gps_loss@3~0", "lasts more than 0 s"),
    ("world:gps_loss@3~5/2", "0 < ON <= PERIOD"),
    ("world:gps_loss@mode=CRUISE", "mode must be one of"),
    ("world:gps_loss@3+2", "+SECONDS follows a condition"),
    ("node1:wrong_output@3:mode=sideways", "mode must be one of bias, random"),
    ("node1:wrong_output@3:volume=11", "has no parameter 'volume'"),
    ("node1:wrong_output@3:value=inf", "is not finite"),
    ("node1:wrong_output@3:value", "'value' is not KEY=VALUE"),
    ("node1:wrong_output@3:axis=elev,axis=ail", "given twice"),
])
def test_mistakes_are_refused_with_one_line(spec: str, says: str) -> None:
    with pytest.raises(FaultSpecError) as err:
        grammar.parse(spec, "f1")
    assert says in str(err.value) and "\n" not in str(err.value)
    assert err.value.exit_code == 2


def test_the_yaml_form(tmp_path: Path) -> None:
    path = tmp_path / "faults.yaml"
    path.write_text("""
faults:
  - spec: nav_fcs@node2:memory_violation@60
  - id: gps
    class: gps_loss
    target: world
    at_s: 100
    duration: {kind: transient, length_s: 30}
  - class: stuck_output
    target: {node: node3, partition: nav_fcs, port: ACT_CMD_OUT}
    trigger: {after: gps, delay_s: 2}
  - class: wrong_output
    target: {node: node1}
    trigger: {mode: AUTOPILOT}
    params: {mode: oscillating, value: 0.2}
""")
    faults = grammar.from_yaml_file(path)
    assert [f.fid for f in faults] == ["f1", "gps", "f3", "f4"]
    assert faults[0] == grammar.parse("nav_fcs@node2:memory_violation@60", "f1")
    assert faults[1].duration.length_s == 30.0 and faults[1].target == Target("world")
    assert faults[2].trigger == Trigger(after="gps", delay_s=2.0)
    assert faults[3].params == {"mode": "oscillating", "value": 0.2}


@pytest.mark.parametrize("text, says", [
    ("faults: []", "faults: [] should be non-empty"),
    ("faults: [{class: gps_loss, target: world}]", "faults.0"),
    ("faults: [{spec: 'world:gps_loss@1', colour: red}]", "faults.0"),
    ("faults: [{spec: 'world:gps_loss@1'}, {spec: 'world:c2_loss@after=f9'}]",
     "after=f9 names no earlier fault"),
    ("faults: [{id: a, spec: 'world:gps_loss@1'}, {id: a, spec: 'world:c2_loss@2'}]",
     "fault id 'a' used twice"),
    ("faults: [{spec: 'world:melt@1'}]", "faults[0]: fault 'world:melt@1': unknown fault class"),
    ("faults: [", "not valid YAML"),
])
def test_yaml_mistakes_name_the_path(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "faults.yaml"
    path.write_text(text)
    with pytest.raises(FaultSpecError) as err:
        grammar.from_yaml_file(path)
    assert says in str(err.value), str(err.value)


def test_the_catalogue_has_thirty_classes_across_every_layer() -> None:
    classes = catalogue.load()
    assert len(classes) >= 30
    assert {c.layer for c in classes.values()} == set(catalogue.LAYERS)
    for c in classes.values():
        assert c.detect["redundant"] and c.outcomes["redundant"], c.name
        if c.known_limit:
            assert c.known_limit["reason"], c.name
        # no fault confined to one replica may be a known limit of a redundant system: a
        # partition or node class declares one that always applies only for common mode
        if c.layer in ("partition", "node") and c.known_limit:
            assert c.known_limit["applies"] != "always", c.name
        for when, case in c.cases:
            if c.layer in ("partition", "node") and case.known_limit and \
                    case.known_limit["applies"] == "always":
                assert when.get("common_mode") is True, (c.name, when)


ROOT = Path(__file__).resolve().parents[2]


def test_every_class_is_documented_and_in_both_shipped_campaigns() -> None:
    import yaml

    doc = (ROOT / "docs" / "fault-injection.md").read_text()
    rows = {line.split("`")[1] for line in doc.splitlines() if line.startswith("| `")}
    classes = set(catalogue.load())
    assert classes <= rows, sorted(classes - rows)
    assert f"one of the catalogue's {len(classes)} classes" in doc
    from ima.campaign import spec

    for name in ("smoke", "full"):
        path = ROOT / "config" / "campaigns" / f"{name}.yaml"
        camp = yaml.safe_load(path.read_text())
        used = {e["class"] for e in camp["faults"] if "class" in e}
        assert classes <= used, (name, sorted(classes - used))
        # it expands into its runs: every target exists in the systems its workloads fly
        assert {r.group for r in spec.load(path).runs} >= classes, name
