# SPDX-License-Identifier: Apache-2.0
"""The example module in real time: windows start on the monotonic clock, jitter is measured
for every window run, and the partitions' own clock readings put them inside their windows.
Bounds are loose on purpose: this must hold on a loaded two-core machine."""

from __future__ import annotations

import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "config" / "examples" / "three_partitions.xml"
FRAMES = 40  # 2 s of 50 ms frames
TOLERANCE_NS = 2_000_000


def test_realtime_run_keeps_its_windows(run_ske, split_windows, partition_written):
    t0 = time.monotonic()
    run = run_ske(EXAMPLE, frames=FRAMES, args=["--realtime"], timeout=60)
    elapsed = time.monotonic() - t0
    assert run.returncode == 0, run.stderr
    (start,) = run.of_kind("module_start")
    assert start["time_mode"] == "realtime"
    maf_ns, table = start["major_frame_ns"], start["windows"]
    # Real time is real: the last window ends (FRAMES - 1) frames after the first starts.
    last_end = (FRAMES - 1) * maf_ns + max(w["offset_ns"] + w["duration_ns"] for w in table)
    assert elapsed >= last_end / 1e9 - 0.01, elapsed

    trace = split_windows(run.events)
    assert len(trace.windows) == FRAMES * len(table)
    late = [w.start["late_ns"] for w in trace.windows]
    assert all(isinstance(v, int) and v >= 0 for v in late)
    assert statistics.median(late) < 5_000_000, late

    # One jitter sample per window the partition ran and handed back.
    ran = [w for w in trace.windows if w.end.get("yielded") is True]
    overruns = run.of_kind("overrun")
    assert len(ran) + len(overruns) == len(trace.windows)
    jitter = run.stats["jitter_us"]
    assert jitter is not None and jitter["count"] == len(ran)
    assert jitter["median"] < 5000, jitter
    assert run.stats["mode"] == "realtime"

    # The partitions' events carry their own CLOCK_MONOTONIC readings: each falls inside one
    # of the partition's windows, and they are real readings, not copies of window starts.
    readings = []
    for w in trace.windows:
        for e in w.inside:
            if not partition_written(e):
                continue
            assert e["src"] == w.partition, e
            t = e.get("reported_t_ns", e["t_ns"])
            assert w.contains(t, TOLERANCE_NS), (e, w.start, w.end)
            readings.append((e["src"], t, t - w.start_ns))
    assert {src for src, _, _ in readings} == {w["partition"] for w in table}
    assert any(offset > 0 for _, _, offset in readings)
    for name in {w["partition"] for w in table}:
        mine = [t for src, t, _ in readings if src == name]
        assert mine == sorted(mine), f"{name}'s clock went back"
