# SPDX-License-Identifier: Apache-2.0
"""Pilot station scripts: the shipped ones load, bad ones get errors naming the bad value."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from imaworld import pilot
from imaworld.pilot import PilotScriptError

PILOTS = Path(__file__).resolve().parents[2] / "sim" / "pilots"


@pytest.mark.parametrize("name", ["default.yaml", "direct.yaml", "c2_loss.yaml", "hold.yaml"])
def test_shipped_scripts_load(name):
    s = pilot.load(PILOTS / name)
    assert s.start["altitude_ft"] == 3000 and s.events


def test_default_script_segments():
    s = pilot.load(PILOTS / "default.yaml")
    assert s.settle_s == 120
    segs = s.autopilot_segments(600)
    assert [(a, b) for a, b, _ in segs] == [(0, 200), (200, 380), (380, 600)]
    assert [(t["heading_deg"], t["altitude_ft"]) for _, _, t in segs] == \
        [(90, 3000), (180, 3000), (180, 4000)]
    assert segs[0][2]["airspeed_kt"] == 100 and segs[0][2]["vert_mode"] == "ALT"


def test_state_is_cumulative():
    s = pilot.load(PILOTS / "c2_loss.yaml")
    assert s.state(0)["mode"] == "DIRECT"
    assert s.state(11)["stick"]["roll"] == 0.1 and s.state(11)["stick"]["pitch"] == 0.0
    assert s.state(30)["c2_link"] == "down" and s.state(90)["c2_link"] == "up"
    assert pilot.load(PILOTS / "direct.yaml").autopilot_segments(60) == []


def _err(doc) -> str:
    with pytest.raises(PilotScriptError) as e:
        pilot.parse(doc, "x.yaml")
    return str(e.value)


START = {"altitude_ft": 3000, "airspeed_kt": 100, "heading_deg": 90}


@pytest.mark.parametrize("doc, where", [
    ({"start": START, "events": [{"t": 0}, {"t": 5, "stick": {"pitch": 1.5}}]},
     "events[1].stick.pitch: 1.5 is greater than the maximum of 1"),
    ({"events": []}, "(top level): 'start' is a required property"),
    ({"start": {**START, "airspeed_kt": "fast"}}, "start.airspeed_kt: 'fast' is not of type"),
    ({"start": START, "events": [{"t": 0, "mode": "AUTO"}]}, "events[0].mode: 'AUTO' is not one"),
    ({"start": START, "events": [{"t": 0, "gear": "down"}]}, "events[0]: Additional properties"),
    ({"start": START, "events": [{"mode": "DIRECT"}]}, "events[0]: 't' is a required property"),
    ({"start": START, "events": [{"t": 10}, {"t": 5}]}, "events[1].t: 5 comes before"),
    ({"start": START, "evaluate": {"settle_s": -1}}, "evaluate.settle_s: -1 is less than"),
    ([1, 2], "(top level): [1, 2] is not of type 'object'"),
    (None, "(top level): None is not of type 'object'"),
])
def test_errors_name_the_bad_value(doc, where):
    msg = _err(doc)
    assert msg.startswith("x.yaml: ") and where in msg, msg


def test_bad_yaml_and_missing_file(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("start: {altitude_ft: 3000\nevents: [")
    with pytest.raises(PilotScriptError, match=r"not valid YAML \(line"):
        pilot.load(f)
    with pytest.raises(PilotScriptError, match="cannot read"):
        pilot.load(tmp_path / "nope.yaml")


def test_cli_reports_a_bad_script_in_one_line(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("start: {altitude_ft: 3000, airspeed_kt: 100, heading_deg: 400}\n")
    p = subprocess.run([sys.executable, "-m", "imaworld", "--bus", str(tmp_path / "s"),
                        "--run-dir", str(tmp_path / "r"), "--pilot", str(f)],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.strip().splitlines() == [
        f"imaworld: {f}: bad pilot script: start.heading_deg: 400 is greater than the "
        "maximum of 360"]
