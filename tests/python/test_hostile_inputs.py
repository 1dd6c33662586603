# SPDX-License-Identifier: Apache-2.0
"""Inputs a careless or hostile user gives the command line: each gets one clear error line
and the documented exit status, never a traceback, a hang or a file written where it should
not be."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from ima.deploy.source import read_source

ROOT = Path(__file__).resolve().parents[2]
SIMPLEX = ROOT / "config" / "systems" / "rpas_simplex.yaml"
IMA = [sys.executable, "-m", "ima"]


def ima(*args: str, cwd: Path = ROOT, timeout: float = 60.0) -> subprocess.CompletedProcess:
    t0 = time.monotonic()
    p = subprocess.run([*IMA, *args], capture_output=True, text=True, cwd=cwd, timeout=timeout)
    p.wall_s = time.monotonic() - t0
    return p


def refused(p: subprocess.CompletedProcess, *says: str, code: int = 2) -> None:
    assert "Traceback" not in p.stderr, p.stderr[-3000:]
    assert p.returncode == code, (p.returncode, p.stderr[-2000:])
    errors = [line for line in p.stderr.splitlines() if "error" in line]
    assert len(errors) == 1, p.stderr
    for s in says:
        assert s in errors[0], errors[0]


def flat_model(tmp_path: Path, drop: str | None = None) -> Path:
    """The simplex model in one file, its paths absolute (optionally without one channel)."""
    src = read_source(SIMPLEX)
    doc = json.loads(json.dumps(src.doc, default=str))
    doc["channels"]["can"]["dbc"] = str((src.base("channels") / "../can/rpas.dbc").resolve())
    doc["channels"]["dds"]["config"] = str(
        (src.base("channels") / doc["channels"]["dds"]["config"]).resolve())
    if drop:
        del doc["channels"][drop]
    path = tmp_path / "model.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


BOMB = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]\n" for k in range(1, 9)) + \
    "system: *a8\n"


@pytest.mark.parametrize("text, says", [
    (BOMB, "more than 1,000,000 values"),
    ("system: &a\n  - *a\n", "nested deeper than 64"),
    ("nodes: " + "[" * 3000 + "]" * 3000 + "\n", "nested deeper than 64"),
], ids=["alias-bomb", "recursive-alias", "deep-nesting"])
def test_a_system_model_beyond_the_yaml_bounds_is_refused_at_once(tmp_path, text, says):
    model = tmp_path / "model.yaml"
    model.write_text(text)
    p = ima("deploy", str(model), "-o", str(tmp_path / "out"))
    refused(p, str(model), "refused", says)
    assert p.wall_s < 20


@pytest.mark.parametrize("drop", ["can", "dds"])
def test_a_model_without_a_channel_section_says_so(tmp_path, drop):
    model = flat_model(tmp_path, drop)
    refused(ima("deploy", str(model), "-o", str(tmp_path / "out")),
            f"'{drop}' is a required property")


def test_the_flat_model_itself_deploys(tmp_path):
    """(the cases above start from a model that is good)"""
    p = ima("deploy", str(flat_model(tmp_path)), "-o", str(tmp_path / "out"), "--json")
    assert p.returncode == 0, p.stderr


def test_a_campaign_file_beyond_the_yaml_bounds_is_refused(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(BOMB)
    refused(ima("campaign", str(path), "--out", str(tmp_path / "out")), "refused",
            "more than 1,000,000 values")


@pytest.mark.parametrize("content, says", [
    (b"start: {altitude_ft: 3000, airspeed_kt: 100, heading_deg: 90}\n# \xff\xfe\n",
     "not a text file in UTF-8"),
    (b"start: {altitude_ft: 3000, airspeed_kt: 100, heading_deg: 90}\n"
     b"events:\n  - {t: 5, mode: DIRECT, stick: {elev: .nan}}\n", "is not a finite number"),
    (b"start: {altitude_ft: 3000, airspeed_kt: 100, heading_deg: .inf}\n",
     "is not a finite number"),
    (b"start: {altitude_ft: 3000, airspeed_kt: 100, heading_deg: 90}\n"
     b"wind: {speed_kt: 10, from_deg: .nan}\n", "is not a finite number"),
    (BOMB.encode(), "more than 1,000,000 values"),
], ids=["not-utf8", "nan-stick", "inf-heading", "nan-wind", "alias-bomb"])
def test_a_bad_pilot_script_is_refused_before_anything_starts(tmp_path, content, says):
    pilot = tmp_path / "pilot.yaml"
    pilot.write_bytes(content)
    p = ima("launch", str(SIMPLEX), "--duration", "2", "--pilot", str(pilot),
            "--run-dir", str(tmp_path / "run"))
    assert "Traceback" not in p.stderr and p.returncode != 0, p.stderr[-2000:]
    assert says in p.stderr, p.stderr
    assert not (tmp_path / "run" / "world.jsonl").exists()


@pytest.mark.parametrize("run_dir, says", [
    ("", "an empty folder name"),
    ("FILE", "exists and is not a folder"),
    ("/dev/null", "a pseudo file system"),
    ("/proc/ima-run", "a pseudo file system"),
], ids=["empty", "a-file", "dev-null", "proc"])
def test_a_run_directory_that_cannot_be_one_is_refused_first(tmp_path, run_dir, says):
    (tmp_path / "FILE").write_text("a file")
    p = ima("launch", str(SIMPLEX), "--duration", "2", "--run-dir", run_dir, cwd=tmp_path)
    assert "Traceback" not in p.stderr and p.returncode == 2, p.stderr[-2000:]
    assert says in p.stderr
    assert sorted(x.name for x in tmp_path.iterdir()) == ["FILE"]  # nothing written here


def test_deploy_writes_through_no_symbolic_link(tmp_path):
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "precious.txt").write_text("keep me")
    out = tmp_path / "out"
    out.mkdir()
    (out / "node1.xml").symlink_to(victim / "precious.txt")
    refused(ima("deploy", str(SIMPLEX), "-o", str(out)), "a symbolic link")
    assert (victim / "precious.txt").read_text() == "keep me"
    (out / "node1.xml").unlink()
    (out / "glue").symlink_to(victim)
    (victim / "io_ports.h").write_text("/* Generated by `ima deploy` from someone else's */\n")
    refused(ima("deploy", str(SIMPLEX), "-o", str(out)), "a symbolic link")
    assert sorted(x.name for x in victim.iterdir()) == ["io_ports.h", "precious.txt"]
    refused(ima("deploy", str(SIMPLEX), "-o", ""), "an empty folder name")
