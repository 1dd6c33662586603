# SPDX-License-Identifier: Apache-2.0
"""A partition cannot reach outside itself through system calls (ARINC 653 Part 1, spatial
partitioning): each forbidden call raises SIGSYS and is never made, whatever the partition
does with the signal, and the other partitions keep their windows."""

from __future__ import annotations

import os
import platform

import pytest

FRAMES = 3
# Each is one partition of the module (program iso_forbidden, Arguments = the action).
ACTIONS = [
    "fork",  # a new process
    "thread",  # a new thread (pthread_create: clone3)
    "exec",  # replace its program
    "open",  # a file, even read-only
    "socket",
    "kill",  # another process (signal 0 to process 1)
    "kill_group",  # its process group
    "ptrace",
    "setrlimit",  # raise its own memory limit
    "shmget",  # System V shared memory
    "vm_read",  # process_vm_readv of another process
    "write_stdin",  # write to a descriptor other than standard output and error
    "cpu_clock",  # read another process's CPU clock
    "mmap_shared",  # a shared mapping of a descriptor that is not one of its ports
]
if platform.machine() == "x86_64":
    ACTIONS += [
        "i386",  # the 32-bit system-call entry (int 0x80), where numbers mean other calls
        "x32",  # the x32 ABI's numbers
    ]
# Coverage builds (`ima test --coverage` sets IMA_COVERAGE) let a partition write any
# descriptor: libgcov writes its counters from the partition.
_COVERAGE = os.environ.get("IMA_COVERAGE") == "1"
CHECKED = [pytest.param(a, marks=pytest.mark.skipif(
    _COVERAGE and a == "write_stdin", reason="a coverage build lets a partition write"))
    for a in ACTIONS]
SIGNAL_GAMES = ["ignored", "blocked"]  # SIGSYS ignored or blocked, then a file created

_runs: dict[str, object] = {}


@pytest.fixture
def run(run_ske, make_module, tmp_path):
    """The module with every forbidden action, run once for this file."""
    if "run" not in _runs:
        parts = [dict(name="bystander", executable="iso_forbidden", arguments="none")]
        parts += [dict(name=a, executable="iso_forbidden", arguments=a) for a in ACTIONS]
        parts += [dict(name=g, executable="iso_forbidden", arguments=f"{g} {tmp_path / g}")
                  for g in SIGNAL_GAMES]
        parts.append(dict(name="handled", executable="iso_forbidden",
                          arguments=f"handled {tmp_path / 'handled'}"))
        module = make_module(tmp_path / "forbidden.xml", parts)
        _runs["run"] = run_ske(module, frames=FRAMES, timeout=60)
        _runs["tmp"] = tmp_path
    r = _runs["run"]
    assert r.returncode == 0, r.stderr
    return r


@pytest.mark.parametrize("action", CHECKED)
def test_forbidden_call_raises_sigsys(run, trace_of, action):
    # (More than once if the partition is restarted after the denial.)
    assert set(trace_of.lines(run, action, "TRY ")) == {f"TRY {action}"}, run.app_messages(action)
    assert trace_of.denial_evidence(run, action), [
        e for e in run.events if e.get("partition") == action or e["src"] == action]
    assert trace_of.lines(run, action, "SURVIVED") == []
    assert trace_of.lines(run, action, "tick") == []  # its initialisation never went on


@pytest.mark.parametrize("game", SIGNAL_GAMES)
def test_ignoring_or_blocking_sigsys_does_not_let_the_call_through(run, trace_of, game):
    assert trace_of.lines(run, game, "TRY ")
    assert trace_of.denial_evidence(run, game)
    assert trace_of.lines(run, game, "SURVIVED") == []
    assert not (_runs["tmp"] / game).exists(), "the file was created"


HANDLED = {
    "handled.open.signals": "1",
    "handled.open.si_code": "1",  # SYS_SECCOMP
    "handled.open.reason": "1",  # SKE_SANDBOX_DENIED_CALL
    "handled.kill.signals": "2",
    "handled.kill.reason": "2",  # SKE_SANDBOX_DENIED_ARGS: kill is allowed, on itself only
    "handled.kill_self.signals": "2",
}


def test_own_sigsys_handler_sees_the_call_which_is_still_not_made(run, trace_of):
    """A partition that replaces the APEX library's SIGSYS handler gets the denied call's
    number and reason in siginfo, and runs on; the call itself never happens."""
    got = trace_of.checks(run, "handled")
    for name, expected in HANDLED.items():
        assert got[name][1] == expected, (name, got[name])
    # Known to the partition only: its machine's call numbers and ABI.
    for name in ("handled.open.si_syscall", "handled.kill.si_syscall", "handled.open.si_arch",
                 "handled.open.returned", "handled.i386.signals", "handled.i386.reason"):
        if name in got:
            expect, value = got[name]
            assert value == expect, (name, got[name])
    assert not (_runs["tmp"] / "handled").exists(), "the denied open created the file"
    assert trace_of.lines(run, "handled", "tick") == [f"tick {n}" for n in range(FRAMES)]
    assert not trace_of.denial_evidence(run, "handled")


def test_the_others_keep_their_windows(run, trace_of):
    assert trace_of.lines(run, "bystander", "tick") == [f"tick {n}" for n in range(FRAMES)]
    for name in ("bystander", "handled"):
        ends = run.of_kind("window_end", partition=name)
        assert [e["frame"] for e in ends] == list(range(FRAMES))
        assert all(e["yielded"] for e in ends), ends
    assert run.of_kind("overrun") == []
