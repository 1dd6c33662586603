# SPDX-License-Identifier: Apache-2.0
"""Partition_Memory bounds a partition's memory: past it an allocation fails, and the
partition sees the failure (malloc returns NULL with ENOMEM, mmap fails with ENOMEM,
CREATE_PROCESS returns INVALID_CONFIG); it keeps running, and so do the others, in their
own windows. A partition without Partition_Memory has no limit."""

from __future__ import annotations

import pytest

FRAMES = 3
LIMIT_MIB = 16
CHECKS = {
    "big.malloc": "NULL",
    "big.errno": "ENOMEM",
    "big.mmap": "ENOMEM",
    "fill.errno": "ENOMEM",
    "full.create_process": "INVALID_CONFIG",
    "after_free.malloc": "yes",
}

_runs: dict[str, object] = {}


@pytest.fixture
def run(run_ske, make_module, tmp_path):
    if "run" not in _runs:
        module = make_module(tmp_path / "memory.xml", [
            dict(name="limited", executable="iso_memory", arguments=str(LIMIT_MIB),
                 memory_bytes=LIMIT_MIB << 20, window_s="0.2"),
            dict(name="unlimited", executable="iso_memory", arguments="0", window_s="0.2"),
            dict(name="bystander", executable="iso_forbidden", arguments="none",
                 memory_bytes=LIMIT_MIB << 20),
        ], major_frame_s="0.5")
        _runs["run"] = run_ske(module, frames=FRAMES, timeout=60)
    r = _runs["run"]
    assert r.returncode == 0, r.stderr
    return r


def test_allocations_past_the_limit_fail_visibly(run, trace_of):
    got = trace_of.checks(run, "limited")
    for name, expected in CHECKS.items():
        assert got.get(name) == (expected, expected), (name, got.get(name))
    # 1 MiB blocks until one fails: nearly all of the limit (the program's own data, its
    # process stacks and the allocator's headers use the rest), never more.
    fill = int(got["fill.mib"][1])
    assert LIMIT_MIB - 4 <= fill < LIMIT_MIB, fill


def test_the_partition_runs_on_after_hitting_its_limit(run, trace_of):
    assert trace_of.lines(run, "limited", "tick") == [f"tick {n} ok" for n in range(FRAMES)]
    assert not run.of_kind("partition_exit")


def test_no_partition_memory_means_no_limit(run, trace_of):
    assert trace_of.checks(run, "unlimited") == {"unlimited.malloc": ("yes", "yes")}


def test_the_others_keep_their_windows(run, trace_of):
    assert trace_of.lines(run, "bystander", "tick") == [f"tick {n}" for n in range(FRAMES)]
    for name in ("limited", "unlimited", "bystander"):
        ends = run.of_kind("window_end", partition=name)
        assert [e["frame"] for e in ends] == list(range(FRAMES))
        assert all(e["yielded"] for e in ends), ends
    assert run.of_kind("overrun") == []
