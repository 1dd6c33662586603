# SPDX-License-Identifier: Apache-2.0
"""A partition's process that ends on its own: the statistics report how it ended (exit status,
0 included, or signal), whatever the health monitor decided next; a new process clears it.

The faulty partition calls exit() at the third release of its process (hm_rogue `exit0`:
status 0, `exit`: status 7); the observed facts are the trace's partition_exit and hm events
and the statistics file.
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest

FRAMES = 6
PARTITION_EXIT = 10


@dataclass(frozen=True)
class Case:
    name: str
    faulty: str  # hm_rogue's arguments
    action: str | None  # the Partition HM table's action for PARTITION_EXIT; None: no table
    code: int  # the exit status the process ends with
    state: str  # the partition's state at the end, in the statistics
    exit_status: int | None  # what the statistics report
    exits: int = 1  # partition_exit events in the run
    restarts: int = 0


CASES = [
    Case("status 0, default IDLE", "exit0 3", None, 0, "idle", 0),
    Case("status 0, IGNORE", "exit0 3", "IGNORE", 0, "exited", 0),
    Case("status 7, default IDLE", "exit 3", None, 7, "idle", 7),
    # A restart starts a new process: the old one's end no longer describes the partition.
    # Each new process exits at its own third release (frames 2 and 5) and is started again.
    Case("status 0, COLD_START", "exit0 3", "COLD_START", 0, "running", None, exits=2,
         restarts=2),
]


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_exit_status_in_statistics(case, run_ske, tmp_path, hm):
    table = {"partition": {2: {PARTITION_EXIT: case.action}}} if case.action else {}
    path = hm.write_module(tmp_path, "exit_status", hm.hm_module(case.faulty, **table))
    run = run_ske(path, frames=FRAMES, timeout=30)
    assert run.returncode == 0, hm.context(run)
    # The process ended with that status.
    exits = run.of_kind("partition_exit", partition=hm.FAULTY)
    assert exits and all((e["status"], e["code"]) == ("exited", case.code) for e in exits), \
        hm.context(run)
    (_, decision), *_ = hm.hm_events(run.events)
    assert decision["error"] == "PARTITION_EXIT", decision
    assert decision["message"] == f"exited with status {case.code}", decision
    faulty = hm.stats_of(run, hm.FAULTY)
    assert (len(exits), faulty["restarts"]) == (case.exits, case.restarts), hm.context(run)
    assert (faulty["state"], faulty["exit_status"], faulty["exit_signal"]) == \
        (case.state, case.exit_status, None), faulty
    healthy = hm.stats_of(run, hm.HEALTHY)
    assert (healthy["state"], healthy["exit_status"], healthy["exit_signal"]) == \
        ("running", None, None), healthy
