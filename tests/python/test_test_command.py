# SPDX-License-Identifier: Apache-2.0
"""Tests of how `ima test` judges its runners: no tests collected is a failure."""

from __future__ import annotations

from pathlib import Path

import pytest

from ima.commands.test import (
    Outcome,
    ctest_command,
    ctest_outcome,
    pytest_command,
    pytest_outcome,
    summary,
)


def test_pytest_exit_0_is_ok():
    assert pytest_outcome(0) == Outcome("pytest", True)


def test_pytest_no_tests_collected_is_a_failure():
    outcome = pytest_outcome(5)
    assert not outcome.ok
    assert "no tests collected" in str(outcome)


@pytest.mark.parametrize(
    ("code", "reason"),
    [
        (1, "tests failed"),
        (2, "interrupted"),
        (3, "internal error"),
        (4, "usage error"),
        (42, "exit code 42"),
        (-9, "killed by signal 9"),
    ],
)
def test_pytest_other_exit_codes_fail_with_a_reason(code, reason):
    outcome = pytest_outcome(code)
    assert not outcome.ok
    assert outcome.reason == reason


def test_ctest_failures():
    assert ctest_outcome(0).ok
    assert not ctest_outcome(8).ok
    assert str(ctest_outcome(8)) == "ctest: FAILED (exit code 8)"


def test_summary_line_and_exit_code():
    assert summary([Outcome("ctest", True), Outcome("pytest", True)]) == (
        "ctest: ok, pytest: ok",
        0,
    )
    line, code = summary([Outcome("ctest", True), pytest_outcome(5)])
    assert code == 1
    assert line.startswith("ctest: ok, pytest: FAILED (no tests collected")
    assert summary([ctest_outcome(8)]) == ("ctest: FAILED (exit code 8)", 1)


def test_pytest_command_passes_keyword_and_drops_cache_on_ci():
    tests = Path("/r/tests")
    assert pytest_command("py", tests, None, {}) == ["py", "-m", "pytest", "/r/tests", "-q"]
    assert pytest_command("py", tests, "vote and not slow", {"CI": "true"}) == [
        "py",
        "-m",
        "pytest",
        "/r/tests",
        "-q",
        "-k",
        "vote and not slow",
        "-p",
        "no:cacheprovider",
    ]
    assert "no:cacheprovider" not in pytest_command("py", tests, None, {"CI": "false"})


def test_ctest_command_fails_on_no_tests():
    cmd = ctest_command(Path("/r/build"))
    assert cmd[:3] == ["ctest", "--test-dir", "/r/build"]
    assert "--no-tests=error" in cmd and "--output-on-failure" in cmd
