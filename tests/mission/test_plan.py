# SPDX-License-Identifier: Apache-2.0
"""Mission plans are checked whole: every broken plan is refused with one line naming the file
and the path of the bad value; the shipped plans pass."""

from __future__ import annotations

import math

import pytest

from ima.mission import plan

from .conftest import MISSIONS


def _set(doc: dict, path: str, value) -> None:
    """Sets doc[path] for a path like legs.1.fix (a number indexes a list)."""
    *parents, last = [int(p) if p.isdigit() else p for p in path.split(".")]
    node = doc
    for p in parents:
        node = node[p]
    if value is _DELETE:
        del node[last]
    else:
        node[last] = value


_DELETE = object()

BROKEN = [
    ("legs.1.fix", "WP9", "legs[1].fix: 'WP9' is not a waypoint (waypoints: A, B, C, BC)"),
    ("legs.1.airspeed_kt", 400, "legs[1].airspeed_kt: 400 is greater than the maximum of 300"),
    ("legs.1.airspeed_kt", 140, "legs[1].airspeed_kt: 140 kt is outside the envelope 65..125 kt"),
    ("legs.1.radius_m", 500, "legs[1]: 'radius_m' is not a field of a TF leg (fields: fix,"),
    ("legs.1.type", "XF", "legs[1].type: 'XF' is not one of ['IF', 'TF'"),
    ("legs.2.laps", _DELETE, "legs[2]: 'laps' is a required property"),
    ("legs.2.leg_time_s", 0, "legs[2].leg_time_s: 0 is less than or equal to the minimum of 0"),
    ("legs.2.turn", "up", "legs[2].turn: 'up' is not one of ['left', 'right']"),
    ("legs.0.type", "TF", "legs[0].type: 'TF': a mission starts with an IF leg"),
    ("legs.3", {"type": "IF", "fix": "C"}, "legs[3].type: IF starts the mission and nothing else"),
    ("cruise.altitude_ft", math.nan, "cruise.altitude_ft: nan is not a finite number"),
    ("cruise.airspeed_kt", math.inf, "cruise.airspeed_kt: inf is not a finite number"),
    ("plan_id", -1, "plan_id: -1 is less than the minimum of 0"),
    ("plan_id", 2**32, "plan_id: 4294967296 is greater than the maximum of 4294967295"),
    ("mission", "9lives", "mission: '9lives' does not match"),
    ("waypoints.1.name", "A", "waypoints[1].name: 'A' names an earlier waypoint already"),
    ("waypoints.1.lat_deg", 48.0,
     "waypoints[1]: 111.3 km from the origin: the plan's local frame is flat"),
    ("runways.0.name", "B", "runways[0].name: 'B' names a waypoint already"),
    ("runways.0.aim_point_m", 1600, "runways[0].aim_point_m: 1600 m is not on the runway"),
    ("limits", {"min_airspeed_kt": 130}, "limits.min_airspeed_kt: 130 kt is not below"),
    ("contingencies.gps_loss", {"detect_s": 1, "action": "avoid", "offset_deg": 30,
                                "altitude_offset_ft": 100},
     "contingencies.gps_loss.action: 'avoid' is for traffic only"),
    ("contingencies.gps_loss", {"detect_s": 1}, "contingencies.gps_loss: needs an action"),
    ("contingencies.gps_loss", {"detect_s": 1, "action": "procedure"},
     "contingencies.gps_loss: action 'procedure' needs a procedure"),
    ("contingencies.gps_loss", {"detect_s": 1, "action": "hold",
                                "procedure": [{"type": "DF", "fix": "A"}]},
     "contingencies.gps_loss.procedure: only with action 'procedure' (this one is 'hold')"),
    ("contingencies.traffic.offset_deg", _DELETE,
     "contingencies.traffic: action 'avoid' needs offset_deg and altitude_offset_ft"),
    ("contingencies.flight_termination", {"detect_s": 1, "action": "terminate", "resume": True},
     "contingencies.flight_termination.resume: a flight termination does not resume"),
    ("contingencies.c2_loss.procedure.0", {"type": "TF", "fix": "A"},
     "contingencies.c2_loss.procedure[0].type: a procedure cannot start with TF"),
    ("contingencies.c2_loss.procedure.0.fix", "Z",
     "contingencies.c2_loss.procedure[0].fix: 'Z' is not a waypoint"),
    ("contingencies.c2_loss.detect_s", _DELETE,
     "contingencies.c2_loss: 'detect_s' is a required property"),
    ("legs.3", {"type": "AUTOLAND", "runway": "RWY27"},
     "legs[3].runway: 'RWY27' is not a runway (runways: RWY09)"),
    ("legs.2", {"type": "AUTOLAND", "runway": "RWY09"},
     "legs[3]: follows the AUTOLAND of legs[2], which ends the mission"),
    ("legs.2", {"type": "ORBIT", "fix": "B", "radius_m": 900, "turn": "left"},
     "legs[2]: an ORBIT needs laps or time_s (one of them)"),
    ("legs.2", {"type": "ORBIT", "fix": "B", "radius_m": 300, "turn": "left", "laps": 1},
     "legs[2].radius_m: 300 m is a tighter turn than the aircraft flies at 100 kt"),
    ("legs.2", {"type": "DUBINS", "fix": "C", "course_deg": 0, "radius_m": 200},
     "legs[2].radius_m: 200 m is a tighter turn"),
    ("legs.2", {"type": "SCAN", "fix": "B", "direction_deg": 0, "length_m": 1000,
                "spacing_m": 0, "passes": 2, "side": "left"},
     "legs[2].spacing_m: 0 is less than or equal to the minimum of 0"),
    ("legs.2", {"type": "RF", "fix": "C", "center": "BC", "turn": "right"},
     "legs[2].center: 'BC' is 1000 m from the arc's start (B) and 3000 m from its end (C): an "
     "RF arc keeps one radius"),
    ("legs.2", {"type": "CA", "course_deg": 90, "altitude_ft": 4000},
     "legs[3]: an RF arc starts over the fix the previous leg ends over, and legs[2] (CA) ends "
     "over none"),
    ("legs.1.altitude_ft", 6000, "legs[1].altitude_ft: climb of 3000 ft needs 12.4 km at 800 "
     "ft/min and 107 kt true; the leg is 4.0 km"),
    ("legs.3.fix", "B", "legs[3].fix: 'B' is where the previous leg ends (a TF of no length)"),
    ("legs.3", {"type": "AUTOLAND", "runway": "RWY09"}, "legs[3]: the final begins 11.2 km "
     "before the threshold at 3000 ft, 528 ft above the 3° glide path"),
]


@pytest.mark.parametrize(("path", "value", "expected"), BROKEN,
                         ids=[f"{p}={v!r}"[:60] for p, v, _ in BROKEN])
def test_a_broken_plan_is_one_line_naming_the_bad_value(doc, path, value, expected):
    if expected.startswith("legs[3]: an RF"):  # an RF after a leg that ends over no fix
        doc["legs"][3] = {"type": "RF", "fix": "C", "center": "BC", "turn": "right"}
    _set(doc, path, value)
    with pytest.raises(plan.MissionPlanError) as exc:
        plan.parse(doc, "x.yaml")
    message = str(exc.value)
    assert message.startswith("x.yaml: " + expected), message
    assert "\n" not in message
    assert exc.value.exit_code == 2


def test_too_many_legs_for_an_image(doc):
    doc["legs"] = [{"type": "IF", "fix": "A"}] + [
        {"type": "TF", "fix": "B" if i % 2 == 0 else "A"} for i in range(46)]
    assert len(plan.parse(doc, "x.yaml").image_legs()) == 48  # the c2_loss procedure's DF too
    doc["legs"].append({"type": "TF", "fix": "A" if doc["legs"][-1]["fix"] == "B" else "B"})
    with pytest.raises(plan.MissionPlanError, match=r"^x.yaml: legs: 49 legs \(48 of the "
                       r"mission, 1 of the procedures\); an image holds 48 at most$"):
        plan.parse(doc, "x.yaml")


def test_the_plan_as_loaded(doc):
    p = plan.parse(doc, "x.yaml")
    assert (p.origin_lat_deg, p.origin_lon_deg) == (47.0, 8.0)  # the first waypoint
    assert p.limits == plan.Limits(65.0, 125.0, 25.0, 800.0)
    assert (p.traffic_h_m, p.traffic_v_ft) == (1000.0, 500.0)
    assert list(p.contingencies) == ["c2_loss", "traffic"]
    c2 = p.contingencies["c2_loss"]
    assert (c2.action, c2.continue_s, c2.resume) == ("procedure", 0.0, True)
    assert p.contingencies["traffic"].continue_s is None
    hm = p.legs[2]
    assert (hm.type, hm.course_deg, hm.turn, hm.leg_time_s, hm.laps) == ("HM", 90.0, "right",
                                                                        60.0, 1)
    assert [(leg.type, part) for leg, part in p.image_legs()] == [
        ("IF", None), ("TF", None), ("HM", None), ("TF", None), ("DF", "c2_loss")]


@pytest.mark.parametrize("name", ["demo", "legs", "tf_square"])
def test_the_shipped_plans_pass(name):
    p = plan.load(MISSIONS / f"{name}.yaml")
    assert p.name == name


def test_legs_yaml_has_every_leg_type():
    p = plan.load(MISSIONS / "legs.yaml")
    types = {leg.type for leg, _ in p.image_legs()}
    assert types >= {"IF", "TF", "DF", "CF", "RF", "CA", "FA", "VA", "HA", "HF", "HM", "DUBINS",
                     "SCAN", "ORBIT", "DIRECT", "AUTOLAND"}
    assert {c.action for c in p.contingencies.values()} == set(plan.ACTIONS)


@pytest.mark.parametrize(("content", "expected"), [
    (b"legs: [a\n", "x.yaml: not valid YAML (line 2, column 1)"),
    (b"\xff\xfe", "x.yaml: not a text file in UTF-8 (byte 0"),
    (b"a: &a [*a]\n", "x.yaml: "),
    (b"- 1\n", "x.yaml: (top level): [1] is not of type 'object'"),
])
def test_a_file_that_is_no_plan(tmp_path, monkeypatch, content, expected):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "x.yaml").write_bytes(content)
    with pytest.raises(plan.MissionPlanError) as exc:
        plan.load("x.yaml")
    assert str(exc.value).startswith(expected) and "\n" not in str(exc.value)


def test_a_missing_or_huge_file(tmp_path):
    with pytest.raises(plan.MissionPlanError, match="cannot read the mission plan"):
        plan.load(tmp_path / "none.yaml")
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (plan.MAX_FILE_BYTES + 1))
    with pytest.raises(plan.MissionPlanError, match="refused: larger than"):
        plan.load(big)
