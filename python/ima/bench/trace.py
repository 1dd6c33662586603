# SPDX-License-Identifier: Apache-2.0
"""`ima bench trace`: what recording costs and how fast the CAN analysis is.

- record_overhead: the wall time of `ima launch` of the triplex (--duration, default 120 s)
  with the recording over without it (--no-recording), minus 1: `pairs` back-to-back pairs,
  alternating which goes first; the median of the per-pair ratios (target ≤ 0.10);
- stats_s_10min: `ima trace stats --json` on the run.mcap of a 10-minute triplex flight, the
  whole command (target ≤ 2 s);
- stats_s_1h: the same on a 1-hour recording, made of six copies of the 10-minute flight's
  CAN frames one after the other (target ≤ 10 s);
- pycan_read_ratio: `ima trace stats`'s reading and analysis (in this process) of that
  flight's frames exported as BLF, then ASC, against python-can's own reader merely reading
  the file (target ≤ 1.5; the larger of two);
- recording_mb_10min: the size of the 10-minute recording.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ima import paths

TARGETS = {"record_overhead": 0.10, "stats_s_10min": 2.0, "stats_s_1h": 10.0,
           "pycan_read_ratio": 1.5}


def _ima(*args: str) -> float:
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "ima", *args], capture_output=True, text=True)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        raise RuntimeError(f"ima {' '.join(args)}: {p.stderr.strip()[-500:]}")
    return wall


def _launch(run_dir: Path, duration: int, record: bool) -> float:
    system = paths.repo_root() / "config" / "systems" / "rpas_triplex.yaml"
    return _ima("launch", str(system), "--duration", str(duration), "--run-dir", str(run_dir),
                "--json", *([] if record else ["--no-recording"]))


def _hour_recording(src: Path, out: Path) -> None:
    """Six copies of a 10-minute recording's CAN frames, one after the other."""
    from ima.recording import mcapread, schemas
    from ima.recording.mcapfile import McapWriter

    msgs = list(mcapread.messages(src, ["/can/frames"]))
    span = max(t for _, t, _ in msgs) + 1
    with open(out, "w+b") as f:
        w = McapWriter(f)
        w.schema(1, "ima.CanFrame", "jsonschema", schemas.CAN_FRAME)
        w.channel(1, 1, "/can/frames", "json")
        seq = 0
        for k in range(6):
            shift = k * span
            for _, t, data in msgs:
                r = json.loads(data)
                r["t_ns"] += shift
                w.message(1, seq, t + shift, json.dumps(r, separators=(",", ":")).encode())
                seq += 1
        w.finish()


def _pycan_read_s(path: Path) -> float:
    import can

    t = time.perf_counter()
    for _ in can.LogReader(str(path)):
        pass
    return time.perf_counter() - t


def measure(duration: int = 120, pairs: int = 3, progress=None) -> dict:
    say = progress or (lambda text: None)
    with tempfile.TemporaryDirectory(prefix="ima-bench-trace-") as tmp:
        tmp = Path(tmp)
        ratios, walls = [], {"with": [], "without": []}
        for i in range(pairs):
            order = (True, False) if i % 2 == 0 else (False, True)
            w = {}
            for rec in order:
                say(f"[{i + 1}/{pairs}] triplex {duration} s {'with' if rec else 'without'} "
                    "recording")
                w[rec] = _launch(tmp / f"p{i}-{int(rec)}", duration, rec)
            walls["with"].append(round(w[True], 2))
            walls["without"].append(round(w[False], 2))
            ratios.append(w[True] / w[False])
        say("triplex 600 s, recorded")
        long_run = tmp / "long"
        _launch(long_run, 600, True)
        rec10 = long_run / "run.mcap"
        say("ima trace stats on the 10-minute recording")
        stats10 = min(_ima("trace", "stats", str(rec10), "--json") for _ in range(2))
        say("a 1-hour recording, and ima trace stats on it")
        hour = tmp / "hour.mcap"
        _hour_recording(rec10, hour)
        stats1h = _ima("trace", "stats", str(hour), "--json")
        ratios_pycan = {}
        for fmt in ("blf", "asc"):
            say(f"python-can's {fmt} reader against ima trace stats")
            log = tmp / f"bus.{fmt}"
            _ima("trace", "export", str(long_run), "--format", fmt, "-o", str(log))
            read = _pycan_read_s(log)
            t = time.perf_counter()
            from ima.trace import columns, stats

            stats.compute(columns.load(log), stats.load_dbc(None))  # as `ima trace stats` does
            ours = time.perf_counter() - t
            ratios_pycan[fmt] = round(ours / read, 2)
        result = {
            "record_overhead": round(statistics.median(ratios) - 1, 3),
            "record_overhead_pairs": [round(r - 1, 3) for r in ratios],
            "launch_wall_s": walls,
            "flight_s": duration,
            "stats_s_10min": round(stats10, 2),
            "stats_s_1h": round(stats1h, 2),
            "pycan_read_ratio": max(ratios_pycan.values()),
            "pycan_read_ratios": ratios_pycan,
            "recording_mb_10min": round(rec10.stat().st_size / 1e6, 1),
        }
    result["targets_met"] = {
        "record_overhead": result["record_overhead"] <= TARGETS["record_overhead"],
        "stats_s_10min": result["stats_s_10min"] <= TARGETS["stats_s_10min"],
        "stats_s_1h": result["stats_s_1h"] <= TARGETS["stats_s_1h"],
        "pycan_read_ratio": result["pycan_read_ratio"] <= TARGETS["pycan_read_ratio"],
    }
    return result


def run(json_out: bool, duration: int = 120, pairs: int = 3) -> int:
    from rich.console import Console

    console = Console(stderr=True)
    with console.status("benchmarking the recording and ima trace") as status:
        r = measure(duration, pairs, progress=lambda text: status.update(text))
    if json_out:
        print(json.dumps(r))
    else:
        for k, v in r.items():
            Console().print(f"  {k:24} {v}")
    return 0
