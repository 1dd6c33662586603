# SPDX-License-Identifier: Apache-2.0
"""`ima bench flight`: a 10-minute single-node flight (`ima launch` of the simplex system, with
its defaults) flown three ways: floating (`speedup`), pinned to one CPU (`speedup_pinned`, and
the CPU time per emulated second of each kind of process), one flight per CPU at once
(`aggregate_speedup`); the floor of its cost (ima.bench.floor); the peak memory of the whole
flight (every process of it, summed); then CAN bus throughput with four clients
(docs/performance.md)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ima import paths
from ima.bench import cpu as cpu_sampler
from ima.bench import floor
from ima.errors import ImaError
from ima.launch import options as launch_options

TARGETS = {"speedup": 50.0, "speedup_pinned": 250.0, "aggregate_speedup": 450.0,
           "canbus_frames_per_s": 100_000.0, "peak_rss_mb": 300.0}
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


def _flown_s(run_dir: Path) -> float:
    truth = (run_dir / "truth.jsonl").read_text().splitlines()
    return json.loads(truth[-1])["t_ns"] / 1e9 if truth else 0.0


def _truth_sha256(run_dir: Path) -> str:
    return hashlib.sha256((run_dir / "truth.jsonl").read_bytes()).hexdigest()


def _launch_cmd(system: Path, duration_s: float, seed: int, run_dir: Path) -> list[str]:
    """`ima launch` with its defaults (deployment, traces, DDS Security, the recording, the
    summary and its plot), as a user runs it; --json, so nobody watches a live view."""
    return [sys.executable, "-m", "ima", "launch", str(system), "--duration", f"{duration_s:g}",
            "--seed", str(seed), "--json", "--run-dir", str(run_dir)]


@contextlib.contextmanager
def _pinned(cpu: int | None):
    """This thread pinned to `cpu` meanwhile (what it starts inherits it), then as before. Not
    a preexec_fn: a fork while other threads run must not run Python code in the child."""
    if cpu is None:
        yield
        return
    saved = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {cpu})
    try:
        yield
    finally:
        os.sched_setaffinity(0, saved)


def fly_once(system: Path, duration_s: float, seed: int, console, cpu: int | None = None,
             what: str = "") -> dict:
    """One `ima launch` of `system`: emulated time flown, wall time (from the command's start
    to its end: deployment and summary included), speed-up, the peak memory of all its
    processes and their CPU time by kind; with `cpu`, every process of it pinned to that
    CPU."""
    with tempfile.TemporaryDirectory(prefix="ima-bench-") as tmp:
        run_dir = Path(tmp) / "run"
        where = "floating" if cpu is None else f"pinned to CPU {cpu}"
        with console.status(f"flying {system.stem} {duration_s:g} s (seed {seed}, light "
                            f"turbulence), {where}{what}"):
            with cpu_sampler.Sampler() as sampler:
                t0 = time.monotonic()
                with _pinned(cpu):
                    proc = subprocess.Popen(_launch_cmd(system, duration_s, seed, run_dir),
                                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                            text=True, cwd=paths.repo_root())
                out, err = proc.communicate()
                wall = time.monotonic() - t0
        done = subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
        if done.returncode != 0:
            raise ImaError(f"benchmark run failed ({done.returncode}): "
                           f"{done.stderr.strip()[-500:]}")
        try:
            summary = json.loads(done.stdout)
        except ValueError as exc:
            raise ImaError(f"ima launch printed no summary: {done.stdout[-300:]!r}") from exc
        failed = {k: v for k, v in (summary.get("returncodes") or {}).items()
                  if v not in (0, None)}
        if failed:
            raise ImaError(f"benchmark run failed: {failed}")
        flown = _flown_s(run_dir)
        sha = _truth_sha256(run_dir)
        cpu_s = {k: v for k, v in sampler.cpu_s_by_kind().items()
                 if not k.startswith("partition:")}
        cpu_s.update(_partitions_cpu_s(run_dir))
    return {"nodes": len(summary.get("nodes") or []), "flight_s": round(flown, 1),
            "wall_s": round(wall, 2), "speedup": round(flown / wall, 1),
            "peak_rss_mb": round(sampler.peak / 2**20, 1),
            "cpu_ms_per_emulated_s": cpu_sampler.per_emulated_s(cpu_s, flown),
            "truth_sha256": sha, "host_stalls": summary.get("host_stall_count") or 0}


def _partitions_cpu_s(run_dir: Path) -> dict[str, float]:
    """Each partition's CPU seconds over every node, as its SKE measured them (exact, where
    the kernel's accounting in /proc counts in ticks of 10 ms)."""
    out: dict[str, float] = {}
    for stats in sorted(run_dir.glob("node*.json")):
        try:
            doc = json.loads(stats.read_text())
        except (OSError, ValueError):
            continue
        for p in doc.get("partitions") or []:
            key = f"partition:{p['name']}"
            out[key] = out.get(key, 0.0) + p.get("cpu_ns", 0) / 1e9
    return out


def fly_aggregate(system: Path, duration_s: float, seed: int, console) -> dict:
    """One flight per CPU at once (`ima launch --json`, each pinned to its own CPU, seeds
    seed, seed+1, ...): the emulated seconds of all of them per wall second of the batch."""
    cpus = sorted(os.sched_getaffinity(0))
    with tempfile.TemporaryDirectory(prefix="ima-bench-") as tmp:
        procs = []
        with console.status(f"flying {len(cpus)} {system.stem} flights of {duration_s:g} s at "
                            "once, one per CPU"):
            t0 = time.monotonic()
            for k, c in enumerate(cpus):
                run_dir = Path(tmp) / f"run{k}"
                cmd = _launch_cmd(system, duration_s, seed + k, run_dir)
                # stderr into a file: a pipe read in turn could hold a flight up
                log = open(Path(tmp) / f"run{k}.err", "w")  # noqa: SIM115 - closed below
                with _pinned(c):
                    procs.append((run_dir, log, subprocess.Popen(
                        cmd, stdout=subprocess.DEVNULL, stderr=log, cwd=paths.repo_root())))
            errors = []
            for run_dir, log, p in procs:
                p.wait()
                log.close()
                if p.returncode != 0:
                    err = Path(log.name).read_text(errors="replace")
                    errors.append(f"{run_dir.name}: exit {p.returncode}: {err.strip()[-300:]}")
            wall = time.monotonic() - t0
        if errors:
            raise ImaError("benchmark flights failed: " + "; ".join(errors))
        flown = [_flown_s(run_dir) for run_dir, _, _ in procs]
    return {"flights": len(procs), "cpus": cpus, "wall_s": round(wall, 2),
            "flight_s": [round(f, 1) for f in flown],
            "aggregate_speedup": round(sum(flown) / wall, 1)}


def measure_flight(system: Path, duration_s: float, seed: int, console) -> dict:
    """The flight three ways: floating on every CPU (`speedup`, the memory, the truth's
    SHA-256), pinned to one CPU (`speedup_pinned`, the CPU time per emulated second of each
    kind of process), and one flight per CPU at once (`aggregate_speedup`)."""
    out = fly_once(system, duration_s, seed, console)
    pinned = fly_once(system, duration_s, seed, console, cpu=min(os.sched_getaffinity(0)))
    agg = fly_aggregate(system, duration_s, seed, console)
    # windows the host stalled (ima launch's host_stalls): such a flight is not a quiet host's
    out["host_stalls"] = {"floating": out.pop("host_stalls"), "pinned": pinned["host_stalls"]}
    out["speedup_pinned"] = pinned["speedup"]
    out["wall_s_pinned"] = pinned["wall_s"]
    out["cpu_ms_per_emulated_s"] = pinned["cpu_ms_per_emulated_s"]
    out["aggregate_speedup"] = agg["aggregate_speedup"]
    out["aggregate"] = agg
    parts = sum(v for k, v in pinned["cpu_ms_per_emulated_s"].items()
                if k.startswith("partition:"))
    out["floor"] = floor.estimate(out["nodes"], parts, floor.jsbsim_ms_per_emulated_s())
    return out


def print_speeds(out, r: dict, targets: dict) -> None:
    """The pinned and aggregate speed-ups, the CPU time by kind of process and the floor."""
    out.print(f"pinned to one CPU: ×{r['speedup_pinned']:.0f} (target ≥ "
              f"{targets['speedup_pinned']:.0f}); one flight per CPU "
              f"({r['aggregate']['flights']}): ×{r['aggregate_speedup']:.0f} aggregate (target ≥ "
              f"{targets['aggregate_speedup']:.0f})")
    cpu = r["cpu_ms_per_emulated_s"]
    out.print("CPU ms per emulated second, pinned: " + ", ".join(
        f"{k} {v:g}" for k, v in cpu.items()))
    f = r["floor"]
    out.print(f"floor: {f['total_ms_per_emulated_s']:g} ms per emulated second (" + ", ".join(
        f"{k} {v:g}" for k, v in f["ms_per_emulated_s"].items())
        + f") → at most ×{f['speedup_floor']:g} on one CPU")


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
        "speedup_pinned": results["speedup_pinned"] >= TARGETS["speedup_pinned"],
        "aggregate_speedup": results["aggregate_speedup"] >= TARGETS["aggregate_speedup"],
        "canbus_frames_per_s":
            (results["canbus_frames_per_s"] or 0) >= TARGETS["canbus_frames_per_s"],
        "peak_rss_mb": results["peak_rss_mb"] < TARGETS["peak_rss_mb"],
    }
    if json_out:
        print(json.dumps(results))
    else:
        out = Console()
        out.print(f"flight: {results['flight_s']:.0f} s emulated in {results['wall_s']:.1f} s wall "
                  f"→ speed-up ×{results['speedup']:.0f} (target ≥ {TARGETS['speedup']:.0f})")
        print_speeds(out, results, TARGETS)
        out.print(f"CAN bus: {results['canbus_frames_per_s'] or 0:,.0f} frames/s with 4 clients "
                  f"(target ≥ {TARGETS['canbus_frames_per_s']:,.0f})")
        out.print(f"peak memory of the whole flight: {results['peak_rss_mb']:.0f} MB "
                  f"(target < {TARGETS['peak_rss_mb']:.0f})")
    return 0
