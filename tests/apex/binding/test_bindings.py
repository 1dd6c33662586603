# SPDX-License-Identifier: Apache-2.0
"""Applications written as for other APEX implementations build with -Werror and run.

test_long_long_time.c keeps times in long long variables and prints them with %lld;
test_cxx_partition.cpp is C++17 using the headers as they are. Both are built by
ima_add_partition (tests/apex/CMakeLists.txt); here they run together under ima-ske, the C one
feeding its time to the C++ one through a sampling channel, and the trace shows what each did.
"""

from pathlib import Path

import pytest

MODULE = Path(__file__).with_suffix(".xml")
FRAMES = 4
MS = 1_000_000


@pytest.fixture
def run(run_ske):
    r = run_ske(MODULE, frames=FRAMES, timeout=30.0)
    assert r.returncode == 0, r.stderr
    assert r.stats["exit_reason"] == "frames"
    return r


def test_the_c_partition_prints_long_long_times(run):
    assert run.app_messages("c_long_long") == [
        f"tick {k} at {20 * k * MS} ns, deadline {(20 * k + 10) * MS} ns, period {20 * MS} ns"
        for k in range(FRAMES)
    ]


def test_the_cxx_partition_runs_its_processes(run):
    started = [e["name"] for e in run.of_kind("process", event="start") if e["src"] == "cxx"]
    assert started == ["producer", "consumer"]
    expected = ["C++ partition ready with 2 processes"]
    for k in range(FRAMES):
        c_time = 20 * k * MS  # written in the C partition's window, read 10 ms later
        expected += [
            f"producer read {c_time} ns from C (VALID, rc 0)",
            f"consumer got item {k} sent at {c_time + 10 * MS} ns, C time {c_time} ns, note {k}",
        ]
    assert run.app_messages("cxx") == expected


def test_nothing_went_wrong(run):
    assert not run.of_kind("hm")
    assert not run.of_kind("partition_exit")
    assert not run.of_kind("events_dropped")
