# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the isolation tests: a module written from a list of partitions, run once per
test file under the real ima-ske, and what its trace says about each partition."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import pytest

CHECK_RE = re.compile(r"^CHECK (\S+) expect=(\S*) got=(\S*)$")


@dataclass
class Part:
    """One partition of a generated module: its program, arguments and confinement."""

    name: str
    executable: str
    arguments: str = ""
    system: bool = False
    memory_bytes: int | None = None  # Partition_Memory SizeBytes; None: no Partition_Memory
    window_s: str = "0.002"


def write_module(path: Path, parts: list[Part], major_frame_s: str = "0.05") -> Path:
    """A module running each partition in one window per major frame, in list order."""
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<ARINC_653_Module xmlns:ima="urn:ima-testbed:arinc653-linux:1" '
        f'ModuleName="{path.stem}">',
        '  <ima:Module_Extension Node="node1" TimeMode="emulated"/>',
    ]
    for i, p in enumerate(parts, 1):
        lines += [
            f'  <Partition PartitionIdentifier="{i}" PartitionName="{p.name}" '
            f'SystemPartition="{"true" if p.system else "false"}">',
            f'    <ima:Linux Executable="{p.executable}" Arguments={quoteattr(p.arguments)}/>',
            "  </Partition>",
        ]
    for i, p in enumerate(parts, 1):
        if p.memory_bytes is not None:
            lines += [
                f'  <Partition_Memory PartitionIdentifier="{i}" PartitionName="{p.name}">',
                f'    <Memory_Requirements Type="DATA" SizeBytes="{p.memory_bytes:#x}" '
                'Access="READ_WRITE"/>',
                "  </Partition_Memory>",
            ]
    lines.append(f'  <Module_Schedule MajorFrameSeconds="{major_frame_s}">')
    offset_us = 0
    for i, p in enumerate(parts, 1):
        lines += [
            f'    <Partition_Schedule PartitionIdentifier="{i}" PartitionName="{p.name}" '
            f'PeriodSeconds="{major_frame_s}">',
            f'      <Window_Schedule WindowIdentifier="{i}" '
            f'WindowStartSeconds="{offset_us / 1e6:.6f}" WindowDurationSeconds="{p.window_s}"/>',
            "    </Partition_Schedule>",
        ]
        offset_us += round(float(p.window_s) * 1e6)
    lines += ["  </Module_Schedule>", "</ARINC_653_Module>", ""]
    path.write_text("\n".join(lines))
    return path


# ---- what the trace says -----------------------------------------------------------------

def messages(run, partition: str) -> list[str]:
    return run.app_messages(partition)


def lines(run, partition: str, prefix: str) -> list[str]:
    return [m for m in messages(run, partition) if m.startswith(prefix)]


def checks(run, partition: str) -> dict[str, tuple[str, str]]:
    """{name: (expected, got)} of the partition's CHECK lines."""
    found = {}
    for text in lines(run, partition, "CHECK "):
        m = CHECK_RE.match(text)
        assert m, f"{partition}: malformed check line {text!r}"
        found[m[1]] = (m[2], m[3])
    return found


def _ended_by(run, partition: str, signal: str, hm_errors: set[str]) -> dict | None:
    """The first trace event saying that `partition` was stopped by `signal`: ima-ske's
    `partition_exit`, or the health monitor's `hm` report of one of `hm_errors`."""
    for e in run.events:
        if e.get("partition") != partition:
            continue
        if e["kind"] == "partition_exit" and e.get("signal") == signal:
            return e
        if e["kind"] == "hm" and e.get("error") in hm_errors:
            return e
    return None


def denial_evidence(run, partition: str) -> dict | None:
    """The trace's evidence that a system call of `partition` was denied (SIGSYS).

    Today a partition has no SIGSYS handler and dies of the signal: `partition_exit` with
    `"signal":"SYS"`. Once the health monitor handles SIGSYS the trace shows its `hm` event
    with error ILLEGAL_REQUEST instead; both are accepted, so the tests need no change then.
    """
    return _ended_by(run, partition, "SYS", {"ILLEGAL_REQUEST"})


def overflow_evidence(run, partition: str) -> dict | None:
    """The trace's evidence that `partition` faulted on a stack guard (SIGSEGV), or the
    health monitor's report of it."""
    return _ended_by(run, partition, "SEGV", {"STACK_OVERFLOW", "MEMORY_VIOLATION"})


# ---- fixtures (test files import nothing from here: pytest runs in importlib mode) -------

@pytest.fixture
def make_module():
    """make_module(path, [dict(name=, executable=, arguments=, system=, memory_bytes=,
    window_s=), ...], major_frame_s="0.05") -> path of the module written."""

    def make(path: Path, parts: list[dict], major_frame_s: str = "0.05") -> Path:
        return write_module(path, [Part(**p) for p in parts], major_frame_s)

    return make


@pytest.fixture
def trace_of():
    """The helpers that read a run's trace about one partition."""

    class TraceOf:
        messages = staticmethod(messages)
        lines = staticmethod(lines)
        checks = staticmethod(checks)
        denial_evidence = staticmethod(denial_evidence)
        overflow_evidence = staticmethod(overflow_evidence)

    return TraceOf
