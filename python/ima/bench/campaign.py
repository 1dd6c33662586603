# SPDX-License-Identifier: Apache-2.0
"""`ima bench campaign`: how fast the campaign runner flies and judges runs.

A campaign of the triplex (config/systems/rpas_triplex.yaml, AUTOPILOT workload) whose runs
each carry one fault of a mix of classes (partition, node, CAN, DDS, sensor), flown for 60 s
and for 300 s, at -j 1 and at -j 2 (one flight per CPU, each pinned to its own):

- runs_per_hour: runs finished per hour of wall time, from the first run started to the last
  one judged (the golden runs, flown once per campaign, are not counted: golden_wall_s);
- parallel_efficiency: runs_per_hour at -j 2 / (2 x runs_per_hour at -j 1);
- runner_overhead: at -j 1, the wall time of the runs over the wall time of their flights, less
  one: what the runner adds (starting each job, judging it against its golden run, writing its
  record) to the flights it runs;
- reflown: flights flown again because the host stalled a partition that was not a target
  (their time counts in the flights');
- violations: run -> the oracles it violated (none expected);
- peak_rss_mb: the peak of the summed resident memory of every process of the benchmark (the
  runner, its workers and their flights).
"""

from __future__ import annotations

import json
import os
import statistics
import tempfile
import time
from pathlib import Path

import yaml

from ima import paths

TARGETS = {"parallel_efficiency": 0.8, "runner_overhead": 0.05}
# One fault of each kind of injector, at 40 % of the flight.
FAULTS = ("nav_fcs@node2:memory_violation", "io@node3:cpu_overrun", "node1:can_drop",
          "node3:dds_drop", "world:gps_loss", "node2:node_crash")
DURATIONS = {"memory_violation": "", "cpu_overrun": "~2", "can_drop": "~0.5", "dds_drop": "~2",
             "gps_loss": "~5", "node_crash": ""}


def _campaign(folder: Path, duration_s: float, runs: int) -> Path:
    at = round(0.4 * duration_s, 1)
    specs = []
    for k in range(runs):
        base = FAULTS[k % len(FAULTS)]
        cls = base.split(":")[1]
        specs.append(f"{base}@{at + 0.05 * (k // len(FAULTS)):g}{DURATIONS[cls]}")
    doc = {
        "campaign": f"bench-{duration_s:g}s",
        "system": str(paths.repo_root() / "config" / "systems" / "rpas_triplex.yaml"),
        "duration_s": duration_s, "seeds": [1], "seed": 1,
        "workloads": {"autopilot": {"pilot": str(paths.repo_root() / "sim" / "pilots" /
                                                 "workload_autopilot.yaml")}},
        "faults": [{"name": f"run{k + 1}", "specs": [s]} for k, s in enumerate(specs)],
    }
    path = folder / f"bench-{duration_s:g}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


class _Clock:
    """A progress listener that keeps the instants the runner reports."""

    def __init__(self) -> None:
        self.t0 = time.monotonic()
        self.goldens_done = None
        self.last = None

    def start(self, goldens: int, runs: int, done: int) -> None:
        pass

    def golden_done(self) -> None:
        self.goldens_done = time.monotonic()

    def run_done(self, record: dict, counts, elapsed: float) -> None:
        self.last = time.monotonic()


def measure(duration_s: float, runs: int, jobs: int, folder: Path) -> dict:
    from ima.campaign import runner, spec

    c = spec.load(_campaign(folder, duration_s, runs))
    out = folder / f"out-{duration_s:g}-j{jobs}"
    clock = _Clock()
    records = runner.run(c, runner.RunnerOptions(out=out, jobs=jobs), clock)
    runs_wall = clock.last - clock.goldens_done
    flights = sum(r["flight_wall_s"] for r in records)
    bad = {r["run_id"]: r["measures"]["oracle_violations"] for r in records
           if r["measures"]["oracle_violations"]}
    return {"runs": len(records), "jobs": jobs, "duration_s": duration_s,
            "golden_wall_s": round(clock.goldens_done - clock.t0, 2),
            "runs_wall_s": round(runs_wall, 2),
            "runs_per_hour": round(3600 * len(records) / runs_wall, 1),
            "flight_wall_s_median": round(statistics.median(r["flight_wall_s"]
                                                            for r in records), 2),
            "runner_overhead": round(runs_wall * jobs / flights - 1, 3) if flights else None,
            "reflown": sum(r.get("refly", 0) for r in records),
            "violations": bad}


def run(json_out: bool, runs_60: int = 8, runs_300: int = 6) -> int:
    from rich.console import Console

    from ima.bench.cpu import Sampler

    console = Console(stderr=True)
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1
    results: dict = {"cpus": cpus, "cases": []}
    with tempfile.TemporaryDirectory(prefix="ima-bench-campaign-") as tmp, Sampler() as rss:
        for duration, n in ((60.0, runs_60), (300.0, runs_300)):
            for jobs in (1, 2):
                with console.status(f"campaign of {n} runs of {duration:g} s at -j {jobs}"):
                    results["cases"].append(measure(duration, n, jobs, Path(tmp)))
    results["peak_rss_mb"] = round(rss.peak / 2**20, 1)
    by = {(c["duration_s"], c["jobs"]): c for c in results["cases"]}
    results["runs_per_hour"] = {f"{d:g}s_j{j}": c["runs_per_hour"] for (d, j), c in by.items()}
    eff = {f"{d:g}s": round(by[(d, 2)]["runs_per_hour"] / (2 * by[(d, 1)]["runs_per_hour"]), 3)
           for d in (60.0, 300.0)}
    results["parallel_efficiency_by_duration"] = eff
    results["parallel_efficiency"] = min(eff.values())
    results["runner_overhead"] = max(by[(d, 1)]["runner_overhead"] for d in (60.0, 300.0))
    results["targets_met"] = {
        "parallel_efficiency": results["parallel_efficiency"] >= TARGETS["parallel_efficiency"],
        "runner_overhead": results["runner_overhead"] <= TARGETS["runner_overhead"],
    }
    if json_out:
        print(json.dumps(results))
        return 0
    out = Console()
    for c in results["cases"]:
        out.print(f"{c['runs']} runs of {c['duration_s']:g} s at -j {c['jobs']}: "
                  f"{c['runs_per_hour']:.0f} runs/hour (a flight {c['flight_wall_s_median']:.1f} s"
                  f" wall; runner overhead {100 * c['runner_overhead']:.1f} %)")
    out.print(f"parallel efficiency at -j 2: {results['parallel_efficiency']:.2f} "
              f"(target ≥ {TARGETS['parallel_efficiency']}); runner overhead "
              f"{100 * results['runner_overhead']:.1f} % (target ≤ "
              f"{100 * TARGETS['runner_overhead']:.0f} %); peak memory "
              f"{results['peak_rss_mb']:.0f} MB")
    return 0
