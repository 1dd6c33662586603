# SPDX-License-Identifier: Apache-2.0
"""A system partition (SystemPartition="true") may open files and sockets, on this machine
only in this test, and is confined all the same: it cannot fork. A normal partition of the
same module cannot open the file the system partition wrote."""

from __future__ import annotations

import pytest

FRAMES = 2
IO_CHECKS = {
    "file.create": "ok",
    "file.write": "30",
    "file.reopen": "yes",
    "file.read_back": "yes",
    "socketpair": "ok",
    "socketpair.send": "1",
    "socketpair.recv": "1",
    "socketpair.byte": str(ord("x")),
    "udp.socket": "ok",
    "udp.bind": "ok",
    "udp.getsockname": "ok",
    "udp.sendto": "1",
    "udp.recvfrom": "1",
    "udp.byte": str(ord("y")),
    "seccomp_mode": "2",
}

_runs: dict[str, object] = {}


@pytest.fixture
def run(run_ske, make_module, tmp_path):
    if "run" not in _runs:
        data = tmp_path / "io.txt"
        module = make_module(tmp_path / "system.xml", [
            dict(name="io", executable="iso_io", arguments=str(data), system=True),
            dict(name="io_fork", executable="iso_forbidden", arguments="system_fork",
                 system=True),
            dict(name="normal", executable="iso_forbidden", arguments="open"),
        ])
        _runs["run"] = run_ske(module, frames=FRAMES, timeout=60)
        _runs["data"] = data
    r = _runs["run"]
    assert r.returncode == 0, r.stderr
    return r


def test_system_partition_opens_files_and_sockets(run, trace_of):
    assert trace_of.checks(run, "io") == {k: (v, v) for k, v in IO_CHECKS.items()}
    assert _runs["data"].read_text() == "written by a system partition\n"
    assert not run.of_kind("partition_exit", partition="io")
    ends = run.of_kind("window_end", partition="io")
    assert len(ends) == FRAMES and all(e["yielded"] for e in ends)


def test_system_partition_cannot_fork(run, trace_of):
    assert set(trace_of.lines(run, "io_fork", "TRY ")) == {"TRY system_fork"}
    assert trace_of.denial_evidence(run, "io_fork")
    assert trace_of.lines(run, "io_fork", "SURVIVED") == []


def test_normal_partition_cannot_open_files(run, trace_of):
    assert trace_of.denial_evidence(run, "normal")
    assert trace_of.lines(run, "normal", "SURVIVED") == []
