# SPDX-License-Identifier: Apache-2.0
"""A run with faults judged against its golden run: the same launch without the faults (flown
into RUN_DIR/golden, or one given), then faultinject's oracles over both."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from ima.errors import ImaError
from ima.launch import run as launch_run
from ima.launch.options import LaunchOptions, LaunchRun


def golden_options(opts: LaunchOptions, run_dir: Path) -> LaunchOptions:
    """The run without its faults (nor the test-only switches that plant violations), into
    run_dir, with the port hashes the oracles compare; as fast as it can go, not served."""
    return dataclasses.replace(opts, faults=[], kill=[], hang=[], wrong_output=[],
                               test_switches=[], run_dir=run_dir, judge=False, golden=None,
                               port_hashes=True, speed=None, live=False)


def fly_golden(opts: LaunchOptions, run_dir: Path) -> Path:
    result = launch_run.launch(golden_options(opts, run_dir))
    failed = {k: v for k, v in result.returncodes.items() if v not in (0, None)}
    if result.interrupted:
        raise KeyboardInterrupt
    if failed:
        raise ImaError(f"the golden run failed: {failed} (logs in {run_dir})")
    return run_dir


def judge(opts: LaunchOptions, result: LaunchRun, system) -> dict:
    """The summary fields of a run with faults: `faults`, `oracles`, `outcome`, ..."""
    from faultinject.judge import judge as judge_run

    golden = Path(opts.golden) if opts.golden else fly_golden(opts, result.run_dir / "golden")
    if not (golden / "truth.jsonl").is_file():
        raise ImaError(f"{golden}: not a run directory (no truth.jsonl)")
    return judge_run(result.run_dir, golden, result.plan, system, opts.duration_s) | {
        "golden": str(golden)}
