# SPDX-License-Identifier: Apache-2.0
"""A stack overflow ends in a fault on a guard, never in another stack: the initialisation
process's (the main thread's, bounded by the stack limit ima-ske sets), an ARINC process's
(the guard page under its stack), and a frame larger than the whole stack (partition code is
compiled to probe its stack page by page, so it cannot jump over the guard)."""

from __future__ import annotations

import pytest

FRAMES = 2
SCENARIOS = ["init", "process", "clash"]

_runs: dict[str, object] = {}


@pytest.fixture
def run(run_ske, make_module, tmp_path):
    if "run" not in _runs:
        parts = [dict(name=s, executable="iso_stack", arguments=s, window_s="0.02")
                 for s in SCENARIOS]
        parts.append(dict(name="bystander", executable="iso_forbidden", arguments="none"))
        module = make_module(tmp_path / "stack.xml", parts, major_frame_s="0.1")
        _runs["run"] = run_ske(module, frames=FRAMES, timeout=60)
    r = _runs["run"]
    assert r.returncode == 0, r.stderr
    return r


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_overflow_faults(run, trace_of, scenario):
    assert set(trace_of.lines(run, scenario, "OVERFLOW ")) == {f"OVERFLOW {scenario}"}
    assert trace_of.overflow_evidence(run, scenario), [
        e for e in run.events if e.get("partition") == scenario]
    assert trace_of.lines(run, scenario, "SURVIVED") == []
    # The process below the overflowing one found its stack as it left it.
    assert "victim stack intact=no" not in trace_of.messages(run, scenario)


def test_the_others_keep_their_windows(run, trace_of):
    assert trace_of.lines(run, "bystander", "tick") == [f"tick {n}" for n in range(FRAMES)]
    ends = run.of_kind("window_end", partition="bystander")
    assert [e["frame"] for e in ends] == list(range(FRAMES)) and all(e["yielded"] for e in ends)
    assert run.of_kind("overrun") == []
