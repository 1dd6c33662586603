# SPDX-License-Identifier: Apache-2.0
"""`ima bench mission`: the mission manager's cost and a long mission's speed.

- The core's CPU time per cycle (`mm_cycle_us_median`, `_p99`, `_max`): the demonstration plan
  flown by the kinematic aircraft of the core's unit tests for a simulated hour (72,000
  cycles), each cycle timed on the thread's CPU clock (`build/.../mission_manager_bench`).
- In the real loop: a one-hour mission (bench/missions/hour.yaml: a sixteen-pass survey, then
  a hold) flown by the triplex (`ima launch` with its defaults: traces, DDS Security,
  recording), with its `speedup` and the mission manager partition's CPU time per window as
  the emulator accounts it (`mm_window_cpu_us_mean`, APEX calls included), against its 10 ms
  window (`mm_window_budget_us`)."""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from ima import paths
from ima.errors import ImaError

CYCLES = 72_000  # an hour of 50 ms cycles
HOUR_S = 3600.0


def _bench_binary() -> Path:
    exe = paths.build_dir() / "partitions" / "mission_manager.build" / "mission_manager_bench"
    if not exe.is_file():
        raise ImaError(f"{exe}: not built (run ./ima to build)")
    return exe


def core_cycles(cycles: int = CYCLES) -> dict:
    from ima.mission import image, plan

    demo = plan.load(paths.repo_root() / "config" / "missions" / "demo.yaml")
    with tempfile.TemporaryDirectory(prefix="ima-bench-mm-") as tmp:
        img = Path(tmp) / "demo.img"
        img.write_bytes(image.encode(demo))
        p = subprocess.run([str(_bench_binary()), str(img), str(cycles)], capture_output=True,
                           text=True, timeout=600)
    if p.returncode != 0:
        raise ImaError(f"mission_manager_bench failed: {p.stderr.strip() or p.stdout.strip()}")
    return json.loads(p.stdout)


def hour_in_the_triplex(duration_s: float) -> dict:
    plan_path = paths.repo_root() / "bench" / "missions" / "hour.yaml"
    with tempfile.TemporaryDirectory(prefix="ima-bench-mission-") as tmp:
        run_dir = Path(tmp) / "run"
        p = subprocess.run([str(paths.repo_root() / "ima"), "launch",
                            str(paths.repo_root() / "config" / "systems" / "rpas_triplex.yaml"),
                            "--mission", str(plan_path), "--duration", f"{duration_s:g}",
                            "--json", "--run-dir", str(run_dir)],
                           capture_output=True, text=True, timeout=int(duration_s) + 1800)
        if p.returncode != 0:
            raise ImaError(f"the triplex mission failed (exit {p.returncode}): "
                           f"{p.stderr.strip()[-400:]}")
        s = json.loads(p.stdout)
        node = json.loads((run_dir / "node1.json").read_text())
    mm = next(x for x in node["partitions"] if x["name"] == "mission_manager")
    return {"duration_s": duration_s, "speedup": s["speedup"], "wall_s": s["wall_s"],
            "crashed": s["crashed"], "final_state": s["mission"]["final_state"],
            "legs_flown": s["mission"]["legs_flown"],
            "mm_window_cpu_us_mean": round(mm["cpu_ns"] / max(mm["windows"], 1) / 1000.0, 2),
            "mm_window_budget_us": mm["window_ns_per_frame"] / 1000.0}


def run(json_out: bool, duration_s: float = HOUR_S) -> int:
    core = core_cycles()
    tri = hour_in_the_triplex(duration_s)
    out = {"mm_cycle_us_median": core["median_us"], "mm_cycle_us_p99": core["p99_us"],
           "mm_cycle_us_max": core["max_us"], "mm_cycles": core["cycles"],
           "mm_window_budget_us": tri["mm_window_budget_us"],
           "mm_window_cpu_us_mean": tri["mm_window_cpu_us_mean"],
           "speedup": tri["speedup"], "triplex": tri}
    if json_out:
        json.dump(out, sys.stdout)
        sys.stdout.write("\n")
    else:
        print(f"mission manager core, {core['cycles']} cycles: median {core['median_us']:.1f} µs, "
              f"p99 {core['p99_us']:.1f} µs, max {core['max_us']:.1f} µs (window "
              f"{tri['mm_window_budget_us']:.0f} µs)")
        print(f"in the triplex, {duration_s:g} s mission: speed-up {tri['speedup']}x, the "
              f"partition's CPU per window {tri['mm_window_cpu_us_mean']} µs on average")
    return 0
