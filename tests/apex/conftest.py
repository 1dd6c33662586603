# SPDX-License-Identifier: Apache-2.0
"""APEX conformance tests: run a test file's module under the real SKE, read its CHECK lines.

Each `test_<call>.py` sits beside its module (`test_<call>.xml`) and partition program
(`test_<call>.c`, built as `apex_t_<call>`) and declares:

- FRAMES: how many major frames to run;
- CHECKS: {partition: {check name: expected value}}; the partitions report every check as
  "CHECK <name> expect=<value> got=<value>" (REPORT_APPLICATION_MESSAGE). Expected values are
  return-code names, state names or numbers. None means the value is only known at run time
  (an identifier): the partition's own expect= must then equal its got=;
- optionally XFAIL: {(partition, check name): reason}, for known deviations of the APEX
  library from ARINC 653 Part 1 (strict: the test fails once the deviation is fixed).

A test function taking `check` is run once per CHECKS entry; the `apex` fixture runs the
module once per file and hands out the same run to every test of that file.
"""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest

CHECK_RE = re.compile(r"^CHECK (\S+) expect=(\S*) got=(\S*)$")

_runs: dict[tuple[str, int], ApexRun] = {}


class ApexRun:
    """One ima-ske run of a conformance module, with the checks its partitions reported."""

    def __init__(self, run, module: Path):
        self.run = run
        self.module = module
        self.events = run.events

    # --- reading ---------------------------------------------------------------------------

    def messages(self, partition: str) -> list[str]:
        return self.run.app_messages(partition)

    def lines(self, partition: str, prefix: str) -> list[str]:
        return [m for m in self.messages(partition) if m.startswith(prefix)]

    def checks(self, partition: str) -> dict[str, tuple[str, str]]:
        found: dict[str, tuple[str, str]] = {}
        names = []
        for text in self.lines(partition, "CHECK "):
            m = CHECK_RE.match(text)
            assert m, f"{partition}: malformed check line {text!r}"
            names.append(m[1])
            found[m[1]] = (m[2], m[3])
        dup = [n for n, c in Counter(names).items() if c > 1]
        assert not dup, f"{partition}: checks reported more than once: {dup}"
        return found

    def of_kind(self, kind: str, **match) -> list[dict]:
        return self.run.of_kind(kind, **match)

    def windows(self, partition: str) -> list[dict]:
        return self.of_kind("window_start", partition=partition)

    def context(self) -> str:
        """What to show when an assertion fails: how the run ended and what it printed."""
        stats = self.run.stats or {}
        states = {p["name"]: p["state"] for p in stats.get("partitions", [])}
        return (
            f"\n  module {self.module.name}: ima-ske exit {self.run.returncode}, "
            f"partition states {states}\n  stderr: {self.run.stderr.strip()[-1500:]}"
        )

    # --- asserting -------------------------------------------------------------------------

    def assert_ran(self) -> None:
        assert self.run.returncode == 0, "ima-ske failed" + self.context()
        assert self.run.stats and self.run.stats["exit_reason"] == "frames", self.context()
        dropped = self.of_kind("events_dropped")
        assert not dropped, f"partition events were lost: {dropped}"

    def assert_check(self, partition: str, name: str, expected: str | int | None) -> None:
        checks = self.checks(partition)
        assert name in checks, (
            f"{partition} reported no CHECK {name} ({len(checks)} checks reported; set-up "
            f"failures: {self.lines(partition, 'SETUP ')})" + self.context()
        )
        expect, got = checks[name]
        if expected is None:
            assert got == expect, f"{partition} {name}: expected {expect}, got {got}"
            return
        expected = str(expected)
        assert expect in ("*", expected), (
            f"{partition} {name}: the partition expects {expect}, the test table {expected}"
        )
        assert got == expected, f"{partition} {name}: expected {expected}, got {got}"

    def assert_complete(self, table: dict[str, dict]) -> None:
        """Every partition reported exactly the checks of the table, and no set-up failed."""
        self.assert_ran()
        for partition, expected in table.items():
            setup = self.lines(partition, "SETUP ")
            assert not setup, f"{partition}: set-up failed: {setup}" + self.context()
            reported = self.checks(partition)
            missing = sorted(set(expected) - set(reported))
            unexpected = sorted(set(reported) - set(expected))
            assert not missing and not unexpected, (
                f"{partition}: {len(reported)} checks reported, {len(expected)} expected; "
                f"missing {missing}, unexpected {unexpected}" + self.context()
            )


@pytest.fixture
def apex(request, run_ske) -> ApexRun:
    """The run of this test file's module (FRAMES major frames), shared by its tests."""
    path = Path(request.module.__file__).with_suffix(".xml")
    frames = request.module.FRAMES
    key = (str(path), frames)
    if key not in _runs:
        _runs[key] = ApexRun(run_ske(path, frames=frames, timeout=30.0), path)
    return _runs[key]


def pytest_generate_tests(metafunc):
    if "check" not in metafunc.fixturenames:
        return
    table = metafunc.module.CHECKS
    xfail = getattr(metafunc.module, "XFAIL", {})
    params = []
    for partition, checks in table.items():
        for name, expected in checks.items():
            reason = xfail.get((partition, name))
            marks = [pytest.mark.xfail(reason=reason, strict=True)] if reason else []
            params.append(
                pytest.param((partition, name, expected), id=f"{partition}:{name}", marks=marks)
            )
    metafunc.parametrize("check", params)
