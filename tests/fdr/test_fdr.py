# SPDX-License-Identifier: Apache-2.0
"""The flight data recorder in a triplex flight: one recording per node that decodes whole,
records that are what the node computed (the SKE's own hash of each NAV_OUT message, the
module's HM decisions), a recording that survives `kill -9` of the whole run, and
`ima fdr`'s documented summary."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from faultinject import grammar
from ima.fdr import records
from ima.launch import run as launch_run
from ima.launch.options import LaunchOptions

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "flight"))  # the flight tests' helpers

from flight_helpers import fly_unless_host_stalled  # noqa: E402

TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"
PILOT = ROOT / "sim" / "pilots" / "workload_autopilot.yaml"
DURATION = 10.0
FRAME_NS = 50_000_000


def _fnv1a64(data: bytes) -> str:
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("fdr") / "run"
    opts = LaunchOptions(system=TRIPLEX, run_dir=run_dir, duration_s=DURATION, seed=4,
                         pilot=PILOT, faults=[grammar.parse("nav_fcs@node2:memory_violation@4",
                                                            "f1")],
                         port_hashes=True, judge=False, kind="test")
    launch_run.launch(opts)
    return run_dir


def test_one_recording_per_node_decodes_whole(flight):
    for node in ("node1", "node2", "node3"):
        rec = records.read(flight / f"{node}.fdr")
        s = rec.summary()
        assert s["torn"] == 0 and s["gaps"] == 0 and s["tail_bytes"] == 0, s
        assert s["starts"] == 1 and rec.starts[0]["node"] == node
        # one frame record per major frame from the first window to the end
        assert abs(s["frames"] - DURATION * 1e9 / FRAME_NS) <= 1, s
        frames = [f["frame"] for f in rec.frames]
        assert frames == list(range(frames[0], frames[0] + len(frames)))
        assert [r["seq"] for r in sorted(rec.starts + rec.frames + rec.hm,
                                         key=lambda r: r["offset"])] == list(range(s["records"]))


def test_records_are_what_the_node_computed(flight):
    """Each recorded navigation message hashes to what the SKE hashed when nav_fcs wrote it
    in the same frame; the HM decisions are the module's, in order."""
    for node in ("node1", "node2", "node3"):
        hashes = {}
        hm = []
        with open(flight / f"{node}.jsonl", encoding="utf-8") as f:
            for line in f:
                e = json.loads(line)
                if e.get("kind") == "port_hash" and e.get("port") == "NAV_OUT":
                    hashes[e["t_ns"] // FRAME_NS] = e["hash"]
                elif e.get("kind") == "hm":
                    hm.append((e["partition"], e["error"], e["action"]))
        data = (flight / f"{node}.fdr").read_bytes()
        rec = records.read(flight / f"{node}.fdr")
        # the message the recorder read is the latest nav_fcs wrote, in this frame or, when
        # nav_fcs did not write (restarting), in an earlier one while it was still valid
        latest, checked = None, 0
        for fr in rec.frames:
            latest = hashes.get(fr["frame"], latest)
            if fr["nav"] is None:
                continue
            off = fr["offset"] + records.HEADER.size + records.FRAME_HEAD.size
            assert _fnv1a64(data[off:off + records.NAV.size]) == latest, (node, fr["frame"])
            checked += 1
        assert checked >= len(hashes) - 1 and checked > 0.35 * len(rec.frames), (node, checked)
        assert [(h["partition"], h["error"], h["action"]) for h in rec.hm] == hm
    node2 = records.read(flight / "node2.fdr")
    assert ("nav_fcs", "MEMORY_VIOLATION") in {(h["partition"], h["error"]) for h in node2.hm}


def test_ima_fdr_prints_its_documented_summary(flight, tmp_path):
    p = subprocess.run([sys.executable, "-m", "ima", "fdr", str(flight), "node1", "--json",
                        "--csv", str(tmp_path / "n1.csv"), "--plot", str(tmp_path / "n1.png")],
                       capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert p.returncode == 0, p.stderr
    s = json.loads(p.stdout)
    for key in ("records", "gaps", "torn", "t_first_s", "t_last_s"):
        assert key in s
    assert s["gaps"] == 0 and s["torn"] == 0 and s["t_last_s"] > DURATION - 0.2
    assert (tmp_path / "n1.png").stat().st_size > 10_000
    assert len((tmp_path / "n1.csv").read_text().splitlines()) == s["frames"] + 1
    bad = subprocess.run([sys.executable, "-m", "ima", "fdr", str(flight), "node9"],
                         capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert bad.returncode == 2 and "node1" in bad.stderr and "Traceback" not in bad.stderr


def test_a_recording_survives_kill_9_of_the_whole_run(tmp_path):
    run_dir = tmp_path / "run"
    p = subprocess.Popen([str(ROOT / "ima"), "launch", str(TRIPLEX), "--duration", "600",
                          "--run-dir", str(run_dir), "--json", "--realtime"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            f = run_dir / "node1.fdr"
            if f.is_file() and f.stat().st_size > 40 * records.RECORD_SIZE:
                break
            time.sleep(0.2)
        time.sleep(1.0)
    finally:
        os.killpg(p.pid, signal.SIGKILL)  # the launcher and everything it started
        p.wait()
    time.sleep(0.5)
    rec = records.read(run_dir / "node1.fdr")
    s = rec.summary()
    assert s["frames"] > 40 and s["gaps"] == 0, s
    assert s["torn"] <= 1 and s["tail_bytes"] < records.RECORD_SIZE, s  # at most the last one


@pytest.mark.parametrize("spec", ["fdr@node1:partition_crash@3~1", "fdr@node1:partition_crash@3",
                                  "fdr@node1:cpu_overrun@3~2", "fdr@node1:partition_hang@3~1",
                                  "fdr@node1:disk_full@3~2"],
                         ids=["killed", "crash-loop", "overrun", "hung", "disk-full"])
def test_the_recorders_loss_changes_nothing(spec, tmp_path):
    """Killed once, crashing in a loop, overrunning its window, hung, its disk full: the
    truth is bit-identical to the run without the fault, and every other partition's windows
    and messages are those of that run (the oracles of docs/fault-injection.md, against its
    golden run)."""
    run_dir = tmp_path / "run"

    def fly() -> dict:
        p = subprocess.run([str(ROOT / "ima"), "launch", str(TRIPLEX), "--duration", "8",
                            "--fault", spec, "--run-dir", str(run_dir), "--json"],
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr[-2000:]
        return json.loads(p.stdout)

    # flown again, once, when the host stalled a partition the fault does not act on
    s = fly_unless_host_stalled(fly, run_dir, spec, targets=frozenset({("node1", "fdr")}))
    o = s["oracles"]
    assert s["faults"][0]["applied"], s["faults"]
    assert o["envelope"]["truth_identical"], o["envelope"]
    for name in ("temporal_isolation", "data_isolation", "hm_action", "detection"):
        assert o[name]["verdict"] == "pass", (name, o[name])
    rec = records.read(run_dir / "node1.fdr")
    assert rec.summary()["torn"] == 0
    errors = [(h["partition"], h["error"]) for h in rec.hm]
    if "partition_crash@3~1" in spec:  # restarted once: it records its own end and the gap
        assert errors == [("fdr", "PARTITION_EXIT")]
        assert len(rec.starts) == 2 and rec.summary()["missing_frames"] >= 1
    if "disk_full" in spec:  # its writes failed for 2 s: restarted, recording again after
        assert errors and set(errors) == {("fdr", "APPLICATION_ERROR")}, errors
        assert len(rec.starts) >= 2 and rec.frames[-1]["t_ns"] > 7.5e9
        assert 30 <= rec.summary()["missing_frames"] <= 45, rec.summary()
    assert s["faults"][0]["outcome"] == "detected_recovered", s["faults"][0]
