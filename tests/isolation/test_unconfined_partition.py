# SPDX-License-Identifier: Apache-2.0
"""ima-ske gives the CPU only to a partition that has confined itself: a program that
attaches without installing the APEX library's system-call filter is refused before its first
grant, with one line naming it, and the module does not run."""

from __future__ import annotations


def test_unconfined_partition_is_refused(run_ske, make_module, tmp_path):
    module = make_module(tmp_path / "unconfined.xml", [
        dict(name="good", executable="iso_forbidden", arguments="none"),
        dict(name="rogue", executable="iso_unconfined"),
    ])
    run = run_ske(module, frames=2, timeout=60)
    assert run.returncode == 1, run.stderr
    lines = run.stderr.splitlines()
    assert len(lines) == 1, run.stderr
    assert "partition 'rogue'" in lines[0] and "not confined" in lines[0], lines[0]
    assert "GRANTED" not in run.stdout
    assert run.of_kind("window_start") == []
    assert run.stats["exit_reason"] == "error"

