# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the launch tests: real runs of the system models (JSBSim world, CAN bus, one
ima-ske per node with its partitions and DDS agent), each run once per session and shared by
the tests that judge it from the world's truth and the recorded traces."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ima.launch import options as launch_options
from ima.launch import run as launch_run
from ima.launch import summary as launch_summary

# The tests import their helpers (launch_helpers.py) from this folder, and the flight tests'
# helpers (bounds) from tests/flight.
HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "flight")]

from flight_helpers import fly_unless_host_stalled  # noqa: E402
from launch_helpers import TRIPLEX, Run  # noqa: E402


class LaunchCache:
    def __init__(self, base: Path) -> None:
        self.base = base
        self.runs: dict[str, Run] = {}

    def launch(self, name: str, system: Path = TRIPLEX, on_status=None, **kw) -> Run:
        if name not in self.runs:
            run_dir = self.base / name
            opts = launch_options.LaunchOptions(system=system, run_dir=run_dir, **kw)
            result = fly_unless_host_stalled(
                lambda: launch_run.launch(opts, on_status=on_status), run_dir, name)
            pilot = Path(opts.pilot) if opts.pilot else launch_options.default_pilot()
            summary = launch_summary.summarise(run_dir, pilot, opts.duration_s, result.nodes,
                                               result.killed, result.wall_s, hung=result.hung)
            self.runs[name] = Run(run_dir, summary, result)
        return self.runs[name]


@pytest.fixture(scope="session")
def launches(tmp_path_factory) -> LaunchCache:
    return LaunchCache(tmp_path_factory.mktemp("launches"))
