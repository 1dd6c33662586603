# SPDX-License-Identifier: Apache-2.0
"""The example module under the real SKE for 1000 major frames: the cyclic plan the trace
shows is the configured one, partitions act only inside their windows, their data flow is
clean, and emulated runs are reproducible byte for byte."""

from __future__ import annotations

import os
import re
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "config" / "examples" / "three_partitions.xml"
FRAMES = 1000
REPORT_EVERY = 20  # the consumer and monitor report once every 20 of their periods


def seconds_ns(text: str) -> int:
    return round(float(text) * 1e9)


def local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def xml_schedule(path: Path) -> tuple[int, list[dict]]:
    """The major frame and the windows (in time order) read from the module XML itself."""
    root = ET.parse(path).getroot()
    (sched,) = [e for e in root.iter() if local(e.tag) == "Module_Schedule"]
    windows = []
    for ps in sched:
        if local(ps.tag) != "Partition_Schedule":
            continue
        for ws in ps:
            if local(ws.tag) == "Window_Schedule":
                windows.append({
                    "window": int(ws.get("WindowIdentifier")),
                    "partition": ps.get("PartitionName"),
                    "offset_ns": seconds_ns(ws.get("WindowStartSeconds")),
                    "duration_ns": seconds_ns(ws.get("WindowDurationSeconds")),
                })
    windows.sort(key=lambda w: w["offset_ns"])
    return seconds_ns(sched.get("MajorFrameSeconds")), windows


@pytest.fixture
def example_run(run_ske):
    run = run_ske(EXAMPLE, frames=FRAMES)
    assert run.returncode == 0, run.stderr
    return run


def test_module_start_announces_the_configured_schedule(example_run):
    maf_ns, windows = xml_schedule(EXAMPLE)
    assert len(windows) >= 2
    (start,) = example_run.of_kind("module_start")
    assert example_run.events[0] is start
    assert start["major_frame_ns"] == maf_ns
    assert start["windows"] == windows
    assert start["time_mode"] == "emulated"


def test_every_frame_runs_every_window_on_time_one_partition_at_a_time(example_run,
                                                                       split_windows):
    maf_ns, table = xml_schedule(EXAMPLE)
    trace = split_windows(example_run.events)  # fails if two windows are ever open at once
    assert len(trace.windows) == FRAMES * len(table)
    for i, w in enumerate(trace.windows):
        frame, k = divmod(i, len(table))
        cfg = table[k]
        where = f"window #{i} (frame {frame})"
        assert (w.partition, w.window, w.frame) == (cfg["partition"], cfg["window"], frame), where
        assert w.start_ns == frame * maf_ns + cfg["offset_ns"], where
        assert w.end_ns == w.start_ns + cfg["duration_ns"], where
        assert w.end["yielded"] is True, where
        assert "partition_state" not in w.start, where
    for a, b in zip(trace.windows, trace.windows[1:], strict=False):
        assert a.end_ns <= b.start_ns, f"{a} overlaps {b}"
    times = [e["t_ns"] for e in example_run.events]
    assert times == sorted(times), "the trace is not in time order"
    assert not example_run.of_kind("overrun")
    assert not example_run.of_kind("partition_exit")
    # Between windows the trace holds only the module's start (schedule, power-on modes)
    # and its end.
    assert {e["kind"] for e in trace.outside} == {"module_start", "mode", "module_stop"}
    (stop,) = example_run.of_kind("module_stop")
    assert example_run.events[-1] is stop
    assert stop["reason"] == "frames" and stop["frames"] == FRAMES
    assert stop["t_ns"] == FRAMES * maf_ns


def test_partition_events_fall_inside_that_partitions_windows(example_run, split_windows,
                                                             partition_written):
    maf_ns, table = xml_schedule(EXAMPLE)
    own = [e for e in example_run.events if partition_written(e)]
    kinds = {e["kind"] for e in own}
    assert {"app_message", "process", "mode"} <= kinds
    # No reported time had to be corrected by the SKE.
    assert not [e for e in example_run.events if "suspect_time" in e]

    # In trace order: each event lies between the start and end of one of its own windows.
    trace = split_windows(example_run.events)
    assert not [e for e in trace.outside if partition_written(e)]
    for w in trace.windows:
        for e in w.inside:
            if partition_written(e):
                assert e["src"] == w.partition, (e, w.start)
                assert w.contains(e["t_ns"]), (e, w.start, w.end)

    # Independently of trace order, against the XML plan: t_ns falls in one of the
    # partition's configured windows.
    for e in own:
        frame, offset = divmod(e["t_ns"], maf_ns)
        assert frame < FRAMES, e
        assert any(cfg["partition"] == e["src"]
                   and cfg["offset_ns"] <= offset <= cfg["offset_ns"] + cfg["duration_ns"]
                   for cfg in table), e


def test_partitions_use_no_cpu_between_their_windows(example_run):
    stats = example_run.stats
    maf_ns, table = xml_schedule(EXAMPLE)
    assert stats["exit_reason"] == "frames" and stats["frames"] == FRAMES
    assert {p["name"] for p in stats["partitions"]} == {w["partition"] for w in table}
    for p in stats["partitions"]:
        per_frame = sum(1 for w in table if w["partition"] == p["name"])
        assert p["windows"] == FRAMES * per_frame, p
        assert p["overruns"] == 0, p
        # CPU time the kernel charged to the partition between its yield and its next grant.
        assert 0 <= p["cpu_outside_windows_ns_max"] < 2_000_000, p


def parse_report(text: str, prefix: str) -> dict[str, int]:
    assert text.startswith(prefix + ":"), text
    fields = dict(re.findall(r"(\w+)=(-?\d+)", text))
    return {k: int(v) for k, v in fields.items()}


def test_example_data_flow_has_no_gaps_and_matches_the_frames(example_run):
    maf_ns, table = xml_schedule(EXAMPLE)
    consumer = [parse_report(t, "consumer") for t in example_run.app_messages("consumer")]
    monitor = [parse_report(t, "monitor") for t in example_run.app_messages("monitor")]
    assert len(consumer) == FRAMES // REPORT_EVERY
    assert len(monitor) == FRAMES // REPORT_EVERY
    for k, r in enumerate(consumer, 1):
        assert r["reads"] == k * REPORT_EVERY, r
        assert r["last"] == k * REPORT_EVERY - 1, r  # the producer's sequence number
        assert r["invalid"] == 0 and r["seq_gaps"] == 0 and r["cmd_errors"] == 0, r
        # The command of the current frame may still wait behind the higher-priority reader.
        assert r["reads"] - 1 <= r["cmds"] <= r["reads"], r
    # The monitor reads, each frame, the state the producer wrote at the start of the same
    # frame: its age is the distance between the two windows.
    producer_at = min(w["offset_ns"] for w in table if w["partition"] == "producer")
    monitor_at = min(w["offset_ns"] for w in table if w["partition"] == "monitor")
    for k, r in enumerate(monitor, 1):
        assert r["reads"] == k * REPORT_EVERY, r
        assert r["invalid"] == 0, r
        assert r["max_age_us"] * 1000 == monitor_at - producer_at, r
    channels = {c["name"]: c for c in example_run.stats["channels"]}
    assert all(c["messages"] == FRAMES and c["overflows"] == 0 for c in channels.values())


def test_two_runs_write_identical_traces(run_ske):
    a = run_ske(EXAMPLE, frames=FRAMES)
    b = run_ske(EXAMPLE, frames=FRAMES)
    assert a.returncode == b.returncode == 0
    assert a.trace_path.stat().st_size > 0
    assert a.trace_path.read_bytes() == b.trace_path.read_bytes()


def test_ima_run_twice_writes_identical_traces(tmp_path):
    env = dict(os.environ, IMA_SKIP_BUILD="1")
    traces = []
    for n in (1, 2):
        cwd = tmp_path / f"run{n}"
        cwd.mkdir()
        p = subprocess.run([str(ROOT / "ima"), "run", str(EXAMPLE), "--frames", "2000",
                            "--trace", "a.jsonl"], cwd=cwd, env=env, capture_output=True,
                           text=True, timeout=120)
        assert p.returncode == 0, p.stderr
        traces.append((cwd / "a.jsonl").read_bytes())
    assert traces[0].count(b"\n") > 2000 * 4
    assert traces[0] == traces[1]
