# SPDX-License-Identifier: Apache-2.0
"""A `--fault` that cannot apply to the module is refused before anything starts: exit status
2 and one line naming the spec and what is wrong with it."""

from __future__ import annotations

import subprocess

import pytest

BAD = {
    "unknown class": ("cosmic_ray:fid=a,at=1s,partition=faulty", "unknown fault class 'cosmic_ray'"),
    "unknown partition": ("memory_violation:fid=a,at=1s,partition=nobody", "unknown partition 'nobody'"),
    "unknown process": ("memory_violation:fid=a,at=1s,partition=faulty,process=nope",
                        "declares no process 'nope'"),
    "unknown port": ("stuck_output:fid=a,at=1s,partition=producer,port=NOPE", "has no port 'NOPE'"),
    "port fault on a destination port": (
        "corrupt_output:fid=a,at=1s,partition=consumer,port=SP_STATE_IN", "cannot apply to port"),
    "sampling fault on a queuing port": (
        "stuck_output:fid=a,at=1s,partition=producer,port=QP_CMD", "needs a source sampling port"),
    "flood of a sampling port": (
        "queuing_flood:fid=a,at=1s,partition=producer,port=SP_STATE", "needs a source queuing port"),
    "foreign write of its own source port": (
        "foreign_port_write:fid=a,at=1s,partition=producer,port=SP_STATE", "needs a destination port"),
    "no destination port to write into": (
        "foreign_port_write:fid=a,at=1s,partition=producer", "has no destination port"),
    "missing partition": ("numeric_error:fid=a,at=1s", "needs partition=NAME"),
    "missing port": ("stuck_output:fid=a,at=1s,partition=producer", "needs port=NAME"),
    "missing at": ("numeric_error:fid=a,partition=faulty", "at=TIME is required"),
    "missing fid": ("numeric_error:at=1s,partition=faulty", "fid=ID is required"),
    "parameter of another class": ("numeric_error:fid=a,at=1s,partition=faulty,port=ROGUE_IN",
                                   "takes no parameter 'port'"),
    "partition of a module reset": ("module_reset:fid=a,at=1s,partition=faulty",
                                    "takes no parameter 'partition'"),
    "bad value": ("cpu_overrun:fid=a,at=1s,partition=faulty,value=lots", "value=lots"),
    "bad time": ("numeric_error:fid=a,at=soon,partition=faulty", "bad time 'soon'"),
}


def refused(fi, tmp_path, text: str, *faults: str) -> str:
    path = tmp_path / "m.xml"
    path.write_text(text)
    trace = tmp_path / "t.jsonl"
    args = [a for f in faults for a in ("--fault", f)]
    p = subprocess.run([str(fi.SKE), "--frames", "1", "--trace", str(trace), *args, str(path)],
                       capture_output=True, text=True, env=fi.ske_env(), timeout=30)
    assert p.returncode == 2, (faults, p.returncode, p.stderr)
    assert p.stderr.count("\n") == 1 and p.stderr.startswith("ima-ske: error: --fault '"), p.stderr
    assert not trace.exists()  # refused before anything started
    return p.stderr


@pytest.mark.parametrize("case", sorted(BAD))
def test_refused_with_one_line(fi, tmp_path, case):
    spec, says = BAD[case]
    line = refused(fi, tmp_path, fi.module(), spec)
    assert spec in line and says in line, line


def test_memory_exhaustion_needs_a_memory_limit(fi, tmp_path):
    line = refused(fi, tmp_path, fi.module(faulty_memory=False),
                   "memory_exhaustion:fid=a,at=1s,partition=faulty")
    assert "no memory limit" in line


def test_repeated_fid_and_too_many_faults(fi, tmp_path):
    line = refused(fi, tmp_path, fi.module(), "numeric_error:fid=a,at=1s,partition=faulty",
                   "numeric_error:fid=a,at=2s,partition=faulty")
    assert "fid 'a' is given twice" in line
    many = [f"numeric_error:fid=n{i},at={i + 1}s,partition=faulty" for i in range(9)]
    assert "more than 8 faults for partition 'faulty'" in refused(fi, tmp_path, fi.module(), *many)


def test_check_refuses_too(fi, tmp_path):
    path = tmp_path / "m.xml"
    path.write_text(fi.module())
    p = subprocess.run([str(fi.SKE), "--check", "--fault", "numeric_error:fid=a,at=1s,partition=x",
                        str(path)], capture_output=True, text=True, env=fi.ske_env(), timeout=30)
    assert p.returncode == 2 and "unknown partition 'x'" in p.stderr
