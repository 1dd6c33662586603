# SPDX-License-Identifier: Apache-2.0
"""Stopping a running module from outside: SIGINT/SIGTERM end ima-ske cleanly (trace closed,
statistics written, partitions gone), SIGKILL takes the partitions with it, and `ima run`
passes Ctrl-C on."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "config" / "examples" / "three_partitions.xml"
EXAMPLE_PROGRAMS = {"ex_producer", "ex_consumer", "ex_monitor"}
RUN_BEFORE_SIGNAL_S = 0.5
STOP_WITHIN_S = 2.0


def last_event(trace: Path) -> dict:
    with trace.open("rb") as f:
        f.seek(0, os.SEEK_END)
        f.seek(max(0, f.tell() - 4096))
        return json.loads(f.read().splitlines()[-1])


def wait_for_example_partitions(run_tag, proc, ske_pid=None):
    """The example's partitions once all three run (children of ima-ske `ske_pid`, if given)."""

    def started():
        assert proc.poll() is None, "the module stopped on its own"
        parts = run_tag.partitions()
        return parts if {Path(p.exe).name for p in parts} == EXAMPLE_PROGRAMS else None

    parts = run_tag.wait_until(started, 10, "the example's three partitions run")
    assert len(parts) == 3
    if ske_pid is not None:
        assert all(p.ppid == ske_pid for p in parts), parts
    return parts


@pytest.fixture
def start_ske(ske_binary, ske_env, tmp_path):
    """start(*options) runs ima-ske on the example with no frame limit and returns
    (process, trace path, stats path); whatever still runs at the end is killed."""
    procs = []

    def start(*extra):
        trace, stats = tmp_path / "trace.jsonl", tmp_path / "stats.json"
        proc = subprocess.Popen(
            [str(ske_binary), "--trace", str(trace), "--stats", str(stats), *extra, str(EXAMPLE)],
            env=ske_env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        procs.append(proc)
        return proc, trace, stats

    yield start
    for proc in procs:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@pytest.mark.parametrize("signo", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_stops_the_module_cleanly(start_ske, run_tag, signo):
    proc, trace, stats = start_ske()
    wait_for_example_partitions(run_tag, proc, ske_pid=proc.pid)
    time.sleep(RUN_BEFORE_SIGNAL_S)
    assert proc.poll() is None

    proc.send_signal(signo)
    try:
        _, err = proc.communicate(timeout=STOP_WITHIN_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"ima-ske still runs {STOP_WITHIN_S:g} s after {signo.name}")
    assert proc.returncode == 128 + signo, err

    stop = last_event(trace)
    assert stop["kind"] == "module_stop" and stop["reason"] == "signal", stop
    assert stop["frames"] > 0
    summary = json.loads(stats.read_text())
    assert summary["exit_reason"] == "signal"
    assert summary["frames"] == stop["frames"]
    # ima-ske stops its partitions before it exits: none is left, not even re-parented.
    assert run_tag.processes() == []


def test_partitions_die_with_a_killed_ske(start_ske, run_tag):
    proc, _, _ = start_ske()
    wait_for_example_partitions(run_tag, proc, ske_pid=proc.pid)
    time.sleep(RUN_BEFORE_SIGNAL_S)
    proc.kill()  # no chance to clean up: the partitions' parent-death signal must do it
    proc.wait(timeout=5)
    run_tag.wait_until(lambda: run_tag.processes() == [], STOP_WITHIN_S,
                       "the partitions are gone")


def test_ima_run_passes_ctrl_c_on(run_tag, tmp_path):
    trace = tmp_path / "a.jsonl"
    env = dict(os.environ, IMA_SKIP_BUILD="1")
    proc = subprocess.Popen([str(ROOT / "ima"), "run", str(EXAMPLE), "--trace", str(trace)],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        wait_for_example_partitions(run_tag, proc)
        time.sleep(RUN_BEFORE_SIGNAL_S)
        proc.send_signal(signal.SIGINT)  # to ima only, as a terminal would send it
        out, err = proc.communicate(timeout=STOP_WITHIN_S + 3)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    # ima ends by the signal itself, so a calling shell sees the interruption.
    assert proc.returncode == -signal.SIGINT, err
    assert "Traceback" not in err, err
    stop = last_event(trace)
    assert stop["kind"] == "module_stop" and stop["reason"] == "signal", stop
    assert "three_partitions" in out  # the summary of what ran is still shown
    assert run_tag.processes() == []
