# SPDX-License-Identifier: Apache-2.0
"""The flight caches fly a run again, once, when the host stalled a partition past its CPU
budget, and only then."""

from __future__ import annotations

import json

import pytest
from flight_helpers import fly_unless_host_stalled, host_stalls

STALL = {"t_ns": 361855000000, "node": "node1", "src": "ske", "kind": "overrun",
         "partition": "io", "window": 1, "frame": 7237, "budget_ns": 5000000,
         "cause": "cpu_budget", "action": "stopped"}
WINDOW_END = dict(STALL, cause="window_end")


def _flight(run_dir, records_per_flight):
    """A stand-in flight that writes the given node-trace records, one list per call."""
    calls = []

    def fly():
        run_dir.mkdir(parents=True, exist_ok=True)
        records = records_per_flight[len(calls)]
        (run_dir / "node1.jsonl").write_text(
            "".join(json.dumps(r, separators=(",", ":")) + "\n" for r in records))
        calls.append(len(calls))
        return len(calls)
    return fly, calls


def test_a_clean_flight_is_flown_once(tmp_path):
    fly, calls = _flight(tmp_path / "r", [[{"kind": "window_end"}]])
    assert fly_unless_host_stalled(fly, tmp_path / "r", "clean") == 1 and calls == [0]


def test_a_host_stall_is_flown_again_once_with_a_warning(tmp_path):
    run_dir = tmp_path / "r"
    fly, calls = _flight(run_dir, [[STALL], [STALL], [STALL]])
    with pytest.warns(UserWarning, match="host stalled"):
        assert fly_unless_host_stalled(fly, run_dir, "stalled") == 2
    assert calls == [0, 1]
    assert host_stalls(run_dir)[0]["trace"] == "node1.jsonl"  # the second is the tests' to judge


def test_other_overruns_are_not_host_stalls(tmp_path):
    (tmp_path / "node2.jsonl").write_text(json.dumps(WINDOW_END, separators=(",", ":")) + "\n")
    assert host_stalls(tmp_path) == []


def test_a_golden_runs_stall_counts_and_a_targets_does_not(tmp_path):
    (tmp_path / "golden").mkdir()
    (tmp_path / "golden" / "node3.jsonl").write_text(
        json.dumps(dict(STALL, node="node3"), separators=(",", ":")) + "\n")
    (tmp_path / "node1.jsonl").write_text(
        json.dumps(dict(STALL, partition="fdr"), separators=(",", ":")) + "\n")
    assert [s["trace"] for s in host_stalls(tmp_path)] == ["golden/node3.jsonl", "node1.jsonl"]
    stalls = host_stalls(tmp_path, frozenset({("node1", "fdr")}))
    assert [s["trace"] for s in stalls] == ["golden/node3.jsonl"]
