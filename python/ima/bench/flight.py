# SPDX-License-Identifier: Apache-2.0
"""`ima bench flight`: speed-up of a 10-minute single-node flight (`ima fly`: the simplex system
launched), CAN bus throughput with four clients, and the peak memory of the whole flight
(every process of it, summed)."""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from ima import paths
from ima.errors import ImaError
from ima.launch import options as launch_options
from ima.launch import run as launch_run

TARGETS = {"speedup": 50.0, "canbus_frames_per_s": 100_000.0, "peak_rss_mb": 300.0}
_PAGE = os.sysconf("SC_PAGE_SIZE")


def _children_map() -> dict[int, list[int]]:
    kids: dict[int, list[int]] = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as f:
                stat = f.read()
        except OSError:
            continue
        # the command name may hold spaces and parentheses: fields start after the last ')'
        fields = stat[stat.rindex(b")") + 2:].split()
        kids.setdefault(int(fields[1]), []).append(int(name))
    return kids


def tree_rss_bytes(root: int) -> int:
    """Resident memory of `root`'s descendants (not root itself), summed."""
    kids = _children_map()
    total = 0
    stack = list(kids.get(root, []))
    while stack:
        pid = stack.pop()
        stack.extend(kids.get(pid, []))
        try:
            with open(f"/proc/{pid}/statm") as f:
                total += int(f.read().split()[1]) * _PAGE
        except (OSError, ValueError, IndexError):
            pass
    return total


class RssSampler:
    """Samples the summed RSS of this process's descendants until stopped; keeps the peak."""

    def __init__(self, period_s: float = 0.1) -> None:
        self.period_s = period_s
        self.peak = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def _loop(self) -> None:
        me = os.getpid()
        while not self._stop.wait(self.period_s):
            self.peak = max(self.peak, tree_rss_bytes(me))

    def __enter__(self) -> RssSampler:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def canbus_throughput() -> dict:
    binary = paths.build_dir() / "nodes" / "ima-canbus-bench"
    if not binary.is_file():
        raise ImaError(f"ima-canbus-bench not built: run ./ima (it builds); expected {binary}")
    out = subprocess.run([str(binary)], capture_output=True, text=True, timeout=300)
    if out.returncode != 0:
        raise ImaError(f"ima-canbus-bench failed ({out.returncode}): {out.stderr.strip()[-400:]}")
    try:
        return json.loads(out.stdout)
    except ValueError as exc:
        raise ImaError(f"ima-canbus-bench printed no JSON: {out.stdout[:200]!r}") from exc


def measure_flight(system: Path, duration_s: float, seed: int, console) -> dict:
    """One run of `system` as `ima launch` runs it (deployment included): emulated time
    flown, wall time, speed-up, and the peak memory of all its processes."""
    with tempfile.TemporaryDirectory(prefix="ima-bench-") as tmp:
        opts = launch_options.LaunchOptions(system=system, duration_s=duration_s, seed=seed,
                                            run_dir=Path(tmp) / "run")
        with console.status(f"flying {system.stem} {duration_s:g} s (seed {seed}, light "
                            "turbulence)"):
            with RssSampler() as rss:
                t0 = time.monotonic()
                result = launch_run.launch(opts)
                wall = time.monotonic() - t0
        failed = {k: v for k, v in result.returncodes.items() if v not in (0, None)}
        if failed:
            raise ImaError(f"benchmark run failed: {failed}")
        truth = (result.run_dir / "truth.jsonl").read_text().splitlines()
        flown = json.loads(truth[-1])["t_ns"] / 1e9 if truth else 0.0
    return {"nodes": len(result.nodes), "flight_s": round(flown, 1), "wall_s": round(wall, 2),
            "speedup": round(flown / wall, 1), "peak_rss_mb": round(rss.peak / 2**20, 1)}


def run(json_out: bool, duration_s: float = 600.0, seed: int = 1) -> int:
    from rich.console import Console

    console = Console(stderr=True)
    results = measure_flight(launch_options.system_path("rpas_simplex"), duration_s, seed,
                             console)
    with console.status("CAN bus throughput, 4 clients"):
        bus = canbus_throughput()
    results["canbus_frames_per_s"] = bus.get("canbus_frames_per_s")
    results["canbus_bench"] = bus
    results["targets_met"] = {
        "speedup": results["speedup"] >= TARGETS["speedup"],
        "canbus_frames_per_s": (results["canbus_frames_per_s"] or 0) >= TARGETS["canbus_frames_per_s"],
        "peak_rss_mb": results["peak_rss_mb"] < TARGETS["peak_rss_mb"],
    }
    if json_out:
        print(json.dumps(results))
    else:
        out = Console()
        out.print(f"flight: {results['flight_s']:.0f} s emulated in {results['wall_s']:.1f} s wall "
                  f"→ speed-up ×{results['speedup']:.0f} (target ≥ {TARGETS['speedup']:.0f})")
        out.print(f"CAN bus: {results['canbus_frames_per_s'] or 0:,.0f} frames/s with 4 clients "
                  f"(target ≥ {TARGETS['canbus_frames_per_s']:,.0f})")
        out.print(f"peak memory of the whole flight: {results['peak_rss_mb']:.0f} MB "
                  f"(target < {TARGETS['peak_rss_mb']:.0f})")
    return 0
