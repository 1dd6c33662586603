# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the system tests: a trace read back as the sequence of windows it shows, and
the processes a run started, found through /proc."""

from __future__ import annotations

import os
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path

import pytest

BUILD = Path(os.environ.get("IMA_BUILD_DIR", Path(__file__).resolve().parents[2] / "build"))
PARTITIONS = BUILD / "partitions"


@dataclass
class Window:
    """One window as the trace shows it: its start and end events and what lies between."""

    partition: str
    window: int
    frame: int
    start_ns: int
    end_ns: int
    start: dict
    end: dict
    inside: list[dict] = field(default_factory=list)

    def contains(self, t_ns: int, tolerance_ns: int = 0) -> bool:
        return self.start_ns - tolerance_ns <= t_ns <= self.end_ns + tolerance_ns

    def of_kind(self, kind: str) -> list[dict]:
        return [e for e in self.inside if e["kind"] == kind]


@dataclass
class WindowedTrace:
    windows: list[Window]
    outside: list[dict]  # events written while no window was open

    def of_partition(self, name: str) -> list[Window]:
        return [w for w in self.windows if w.partition == name]


def _split_windows(events: list[dict]) -> WindowedTrace:
    """Pairs window_start/window_end events in trace order.

    Fails if a window opens while another is open, or closes a window other than the open
    one: the trace would then show two partitions holding the CPU at once.
    """
    windows: list[Window] = []
    outside: list[dict] = []
    current: dict | None = None
    inside: list[dict] = []
    for line, e in enumerate(events, 1):
        if e["kind"] == "window_start":
            assert current is None, (
                f"trace line {line}: window {e['window']} of {e['partition']} starts while "
                f"window {current['window']} of {current['partition']} is still open")
            current, inside = e, []
        elif e["kind"] == "window_end":
            assert current is not None, f"trace line {line}: window_end without window_start"
            key = ("partition", "window", "frame")
            assert all(e[k] == current[k] for k in key), (
                f"trace line {line}: window_end {[e[k] for k in key]} closes "
                f"{[current[k] for k in key]}")
            windows.append(Window(e["partition"], e["window"], e["frame"], current["t_ns"],
                                  e["t_ns"], current, e, inside))
            current = None
        elif current is not None:
            inside.append(e)
        else:
            outside.append(e)
    assert current is None, "the trace ends inside a window"
    return WindowedTrace(windows, outside)


@pytest.fixture
def split_windows():
    """split_windows(events) -> WindowedTrace."""
    return _split_windows


def is_written_by_partition(e: dict) -> bool:
    """Events the partition itself reported (through its APEX library), as opposed to events
    the SKE writes about it (their `src` is "ske")."""
    return e["src"] != "ske"


@pytest.fixture
def partition_written():
    """partition_written(event) -> bool: the event was reported by the partition itself."""
    return is_written_by_partition


# ---- processes a run left behind ---------------------------------------------------------

TAG_VAR = "IMA_SYSTEST_RUN"


@dataclass(frozen=True)
class Proc:
    pid: int
    ppid: int
    exe: str
    state: str  # the one-letter state of /proc/PID/stat


def tagged_processes(tag: str) -> list[Proc]:
    """Live processes whose environment holds TAG_VAR=tag.

    ima-ske hands its environment on to every partition it starts, so tagging the run's
    environment finds all its processes, even once they are re-parented, whatever they call
    themselves in their command line (a partition's argv[0] is its partition name).
    """
    needle = f"{TAG_VAR}={tag}".encode()
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as f:
                if needle not in f.read().split(b"\0"):
                    continue
            exe = os.readlink(f"/proc/{entry}/exe")
            with open(f"/proc/{entry}/stat") as f:
                state, ppid = f.read().rsplit(")", 1)[1].split()[:2]
        except OSError:
            continue  # gone meanwhile, or a zombie whose memory is already released
        if state not in ("Z", "X"):
            found.append(Proc(int(entry), int(ppid), exe, state))
    return found


@dataclass
class RunTag:
    """A tag in the environment of the processes a test starts."""

    tag: str

    @property
    def env(self) -> dict[str, str]:
        return {TAG_VAR: self.tag}

    def processes(self) -> list[Proc]:
        return tagged_processes(self.tag)

    def partitions(self) -> list[Proc]:
        """The tagged processes running a program of the partition folder."""
        folder = PARTITIONS.resolve()
        return [p for p in self.processes() if Path(p.exe).parent == folder]

    def wait_until(self, predicate, timeout: float, what: str):
        deadline = time.monotonic() + timeout
        while True:
            value = predicate()
            if value:
                return value
            if time.monotonic() > deadline:
                raise AssertionError(f"not within {timeout:g} s: {what}")
            time.sleep(0.02)


@pytest.fixture
def run_tag(monkeypatch) -> RunTag:
    """Tags the environment of every process the test starts (run_ske included)."""
    tag = RunTag(uuid.uuid4().hex)
    monkeypatch.setenv(TAG_VAR, tag.tag)
    return tag


@pytest.fixture
def ske_env(run_tag) -> dict[str, str]:
    """The environment for an ima-ske the test starts itself: tagged, partitions findable."""
    return dict(os.environ, IMA_PARTITION_PATH=str(PARTITIONS))
