# SPDX-License-Identifier: Apache-2.0
"""`ima mission check | show | import`: the table, the JSON, a broken plan as one line with
exit status 2, the PNG, and a QGroundControl plan converted into a plan that passes check."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import yaml

from ima import cli
from ima.commands import mission
from ima.mission import plan

from .conftest import MISSIONS

SAMPLE = Path(__file__).parent / "data" / "sample.plan"


def test_mission_is_a_registered_command():
    assert mission in cli.COMMANDS
    args = cli.build_parser().parse_args(["mission", "show", "x.yaml", "-o", "x.png"])
    assert (args.action, args.file, args.output) == ("show", Path("x.yaml"), Path("x.png"))


def test_check_prints_the_legs_the_contingencies_and_the_image(capsys):
    assert cli.main(["mission", "check", str(MISSIONS / "demo.yaml")]) == 0
    out = capsys.readouterr().out
    for text in ("AUTOLAND", "RWY27", "SCAN", "4 passes of 2500 m, 400 m apart", "c2_loss",
                 "terminate", "geometric", "Mission: "):
        assert text in out, text
    size = 200 + 48 * 11
    assert f"image: {size} bytes, crc32 0x" in out


def test_check_json_one_object_per_plan(capsys):
    files = [str(MISSIONS / n) for n in ("demo.yaml", "tf_square.yaml")]
    assert cli.main(["mission", "check", "--json", *files]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2
    demo, square = (json.loads(line) for line in lines)
    assert demo["mission"] == "demo" and demo["image"]["bytes"] == 728
    assert demo["image"]["crc32"].startswith("0x") and len(demo["image"]["crc32"]) == 10
    assert [leg["type"] for leg in square["legs"]] == ["IF", "TF", "TF", "TF", "TF"]
    assert square["length_m"] == pytest.approx(16000, abs=1)
    assert demo["contingencies"]["c2_loss"]["legs"] == [9, 10]
    assert 20 * 60 < demo["duration_s"] < 35 * 60


def test_a_broken_plan_exits_2_with_one_line(tmp_path, capsys, doc):
    doc["legs"][1]["fix"] = "WP9"
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(doc))
    assert cli.main(["mission", "check", str(bad)]) == 2
    captured = capsys.readouterr()
    assert captured.err == (f"ima: error: {bad}: legs[1].fix: 'WP9' is not a waypoint "
                            "(waypoints: A, B, C, BC)\n")
    assert "Traceback" not in captured.err


def test_show_writes_a_png(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["mission", "show", str(MISSIONS / "legs.yaml")]) == 0
    assert capsys.readouterr().out == "legs.png\n"
    assert (tmp_path / "legs.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = tmp_path / "sub.png"
    assert cli.main(["mission", "show", str(MISSIONS / "demo.yaml"), "-o", str(out)]) == 0
    assert out.stat().st_size > 10_000


def test_import_a_qgroundcontrol_plan(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["mission", "import", str(SAMPLE)]) == 0
    captured = capsys.readouterr()
    assert captured.out == "sample.yaml\n"
    assert "mission.items[3]: loiter radius 80 m raised to 650 m" in captured.err
    p = plan.load(tmp_path / "sample.yaml")
    assert [(leg.type, leg.fix or leg.runway) for leg in p.legs] == [
        ("IF", "HOME"), ("TF", "WP1"), ("TF", "WP2"), ("ORBIT", "WP3"), ("ORBIT", "WP4"),
        ("TF", "WP5"), ("AUTOLAND", "RWY09")]
    # takeoff: 762 m above home (152.4 m) is 3000 ft; item 2 is 1066.8 m above sea level
    assert [leg.altitude_ft for leg in p.legs[:3]] == [3000, 3000, 3500]
    loiter_turns, loiter_time = p.legs[3], p.legs[4]
    assert (loiter_turns.turn, loiter_turns.laps, loiter_turns.radius_m) == ("left", 2, 650)
    assert (loiter_time.turn, loiter_time.time_s, loiter_time.radius_m) == ("right", 90, 700)
    rw = p.runways["RWY09"]
    assert (rw.heading_deg, rw.elevation_ft) == (pytest.approx(90.0, abs=0.1), 500)
    assert (p.origin_lat_deg, p.origin_lon_deg) == (47.0, 8.0)
    # the written file passes check, and is not written over without --force
    assert cli.main(["mission", "check", "sample.yaml"]) == 0
    capsys.readouterr()
    assert cli.main(["mission", "import", str(SAMPLE)]) == 2
    assert "exists already (--force writes over it)" in capsys.readouterr().err
    assert cli.main(["mission", "import", str(SAMPLE), "--force", "-o", "again.yaml"]) == 0


def _sample_with(tmp_path: Path, change) -> Path:
    doc = json.loads(SAMPLE.read_text())
    change(doc["mission"]["items"])
    path = tmp_path / "changed.plan"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize(("change", "expected"), [
    (lambda items: items.insert(2, {"type": "ComplexItem", "complexItemType": "survey"}),
     "mission.items[2]: a survey item cannot be converted: only simple items"),
    (lambda items: items[1].update(command=20),
     "mission.items[1].command: MAVLink command 20 cannot be converted"),
    (lambda items: items[1].update(frame=2), "mission.items[1].frame: 2: altitudes relative"),
    (lambda items: items.append(dict(items[1])),
     "mission.items[7]: follows the landing, which ends the mission"),
    (lambda items: items[1]["params"].__setitem__(6, "high"),
     "mission.items[1].params[6]: 'high' is not a number"),
])
def test_import_refuses_what_it_cannot_convert(tmp_path, monkeypatch, capsys, change, expected):
    monkeypatch.chdir(tmp_path)
    path = _sample_with(tmp_path, change)
    assert cli.main(["mission", "import", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ima: error: {path}: {expected}") and err.count("\n") == 1
    assert not (tmp_path / "changed.yaml").exists()


def test_import_refuses_a_file_that_is_not_a_plan(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    shutil.copy(SAMPLE, tmp_path / "x.plan")
    (tmp_path / "x.plan").write_text("{]")
    assert cli.main(["mission", "import", "x.plan"]) == 2
    assert "x.plan: not a JSON file" in capsys.readouterr().err
    (tmp_path / "x.plan").write_text('{"fileType": "Fence"}')
    assert cli.main(["mission", "import", "x.plan"]) == 2
    assert "not a QGroundControl plan" in capsys.readouterr().err
