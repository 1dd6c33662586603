# SPDX-License-Identifier: Apache-2.0
"""`ima test`: runs the whole test suite, C tests through ctest and Python tests through pytest."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ima import code_coverage, paths
from ima.errors import ImaError

# pytest's documented exit codes (pytest.ExitCode), without importing pytest here.
_PYTEST_EXIT = {
    0: None,
    1: "tests failed",
    2: "interrupted",
    3: "internal error",
    4: "usage error",
    5: "no tests collected — a suite that runs nothing counts as a failure",
}


@dataclass(frozen=True)
class Outcome:
    """Result of one test runner: `ok` and, when not ok, why."""

    runner: str
    ok: bool
    reason: str = ""

    def __str__(self) -> str:
        return f"{self.runner}: ok" if self.ok else f"{self.runner}: FAILED ({self.reason})"


def pytest_outcome(returncode: int) -> Outcome:
    if returncode == 0:
        return Outcome("pytest", True)
    if returncode < 0:
        return Outcome("pytest", False, f"killed by signal {-returncode}")
    return Outcome("pytest", False, _PYTEST_EXIT.get(returncode) or f"exit code {returncode}")


def ctest_outcome(returncode: int) -> Outcome:
    if returncode == 0:
        return Outcome("ctest", True)
    if returncode < 0:
        return Outcome("ctest", False, f"killed by signal {-returncode}")
    # ctest exits 8 when tests fail, and non-zero for "no tests" under --no-tests=error.
    return Outcome("ctest", False, f"exit code {returncode}")


def summary(outcomes: Sequence[Outcome]) -> tuple[str, int]:
    """The closing line and the exit code (0 only if every runner passed)."""
    line = ", ".join(str(o) for o in outcomes)
    return line, 0 if all(o.ok for o in outcomes) else 1


# The unit tests, built a second time with AddressSanitizer and UndefinedBehaviorSanitizer.
SANITIZED_TARGETS = ("test_config", "test_port_buf", "test_plan", "test_hm", "test_create",
                     "test_sandbox_policy", "test_canbus_wire", "test_canbus_socket",
                     "test_canbus_client", "test_canbus_wire_oom",
                     "nav_fcs_test_nf_math", "nav_fcs_test_nav", "nav_fcs_test_fcs",
                     "io_test_settings", "io_test_can_rx", "io_test_can_tx", "io_test_redundancy",
                     "test_fi_spec", "test_voter", "test_canbus_fault", "test_fi_wrong_output",
                     "test_dds_fault", "test_agent_hmac", "test_agent_cipher", "test_trace",
                     "fdr_test_fdr", "test_trace_mcap", "mission_manager_test_mm")
# Built with them because a sanitized test runs it.
SANITIZED_HELPERS = ("ima-canbus",)


def sanitizer_commands(root: Path, build: Path) -> list[list[str]]:
    """Configure and build the sanitized unit tests in `build` (a tree of their own)."""
    configure = ["cmake", "-S", str(root), "-B", str(build), "-G", "Ninja",
                 "-DIMA_SANITIZE=ON", "-DCMAKE_BUILD_TYPE=Debug"]
    return [configure, ["cmake", "--build", str(build), "--target", *SANITIZED_TARGETS,
                                   *SANITIZED_HELPERS]]


def ctest_command(build: Path) -> list[str]:
    return ["ctest", "--test-dir", str(build), "--output-on-failure", "--no-tests=error", "-j2"]


def pytest_command(
    python: str, tests: Path, keyword: str | None, env: Mapping[str, str]
) -> list[str]:
    cmd = [python, "-m", "pytest", str(tests), "-q"]
    if keyword:
        cmd += ["-k", keyword]
    if env.get("CI") == "true":
        # CI runs in a fresh clone: a cache would only be litter.
        cmd += ["-p", "no:cacheprovider"]
    return cmd


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "test",
        help="run the whole test suite (ctest + pytest)",
        description="Run the C tests (ctest, in the build tree) then the Python tests "
        "(pytest, tests/). Exits non-zero if either fails or runs no test.",
    )
    parser.add_argument(
        "-k",
        dest="keyword",
        metavar="EXPR",
        help="only pytest tests matching EXPR (passed to pytest -k)",
    )
    only = parser.add_mutually_exclusive_group()
    only.add_argument("--unit-only", action="store_true", help="run ctest only")
    only.add_argument("--py-only", action="store_true", help="run pytest only")
    only.add_argument(
        "--fuzz-long", nargs="?", type=int, const=FUZZ_LONG, default=None, metavar="N",
        help=f"only the fuzzing of the inputs, with N inputs (default {FUZZ_LONG:,}; the "
        "suite's share is 400); its counts go to build/fuzz-long.json")
    only.add_argument(
        "--coverage", action="store_true",
        help="line and branch coverage (gcovr) of ske/, health_monitor/ and nodes/: ctest and "
        "pytest against an instrumented build in build-coverage/, figures per component "
        "printed and written to build-coverage/coverage.json")
    parser.add_argument(
        "--no-sanitize",
        action="store_true",
        help="skip the unit tests under AddressSanitizer and UndefinedBehaviorSanitizer",
    )
    return parser


def _run_ctest(root: Path, build: Path) -> Outcome:
    if not (build / "CTestTestfile.cmake").is_file():
        print(
            f"ima: no CMake build tree with tests in {build} (./ima configures and builds it)",
            file=sys.stderr,
        )
        return Outcome("ctest", False, "no build tree")
    try:
        done = subprocess.run(ctest_command(build), cwd=root)
    except FileNotFoundError:
        return Outcome("ctest", False, "ctest not found: install the Debian package cmake")
    return ctest_outcome(done.returncode)


def _run_sanitized(root: Path, build: Path) -> Outcome:
    """The unit tests again, built with ASan + UBSan in build-asan/: memory and undefined-
    behaviour errors fail the run (-fno-sanitize-recover)."""
    log = build / "ima-build.log"
    build.mkdir(parents=True, exist_ok=True)
    with log.open("w") as f:
        for cmd in sanitizer_commands(root, build):
            done = subprocess.run(cmd, cwd=root, stdout=f, stderr=subprocess.STDOUT)
            if done.returncode != 0:
                print(f"ima: the sanitizer build failed (log: {log})", file=sys.stderr)
                print(log.read_text()[-3000:], file=sys.stderr)
                return Outcome("ctest (ASan+UBSan)", False, "build failed")
    cmd = ctest_command(build) + ["-R", "^(" + "|".join(SANITIZED_TARGETS) + ")$"]
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=1",
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    done = subprocess.run(cmd, cwd=root, env=env)
    outcome = ctest_outcome(done.returncode)
    return Outcome("ctest (ASan+UBSan)", outcome.ok, outcome.reason)


def _run_pytest(root: Path, keyword: str | None) -> Outcome:
    cmd = pytest_command(sys.executable, paths.tests_dir(), keyword, os.environ)
    outcome = pytest_outcome(subprocess.run(cmd, cwd=root).returncode)
    if not outcome.ok and outcome.reason.startswith("no tests"):
        print(
            f"ima: pytest collected no tests{' matching -k ' + keyword if keyword else ''}",
            file=sys.stderr,
        )
    return outcome


FUZZ_LONG = 10_000


def _run_fuzz_long(root: Path, count: int) -> int:
    """tests/fuzz with `count` inputs; prints and keeps its counts."""
    report = paths.build_dir() / "fuzz-long.json"
    env = dict(os.environ, IMA_FUZZ_COUNT=str(count), IMA_FUZZ_REPORT=str(report))
    report.unlink(missing_ok=True)
    cmd = pytest_command(sys.executable, paths.tests_dir() / "fuzz", None, env) + ["-s"]
    outcome = pytest_outcome(subprocess.run(cmd, cwd=root, env=env).returncode)
    if report.is_file():
        print(f"ima: fuzzing counts in {report}: {report.read_text().strip()}")
    print(Outcome("pytest (fuzz)", outcome.ok, outcome.reason))
    return 0 if outcome.ok else 1


def _build_coverage(root: Path, build: Path) -> bool:
    log = build / "ima-build.log"
    build.mkdir(parents=True, exist_ok=True)
    print(f"ima: building the instrumented tree in {build} (log: {log})", flush=True)
    with log.open("w") as f:
        for cmd in code_coverage.configure_commands(root, build):
            if subprocess.run(cmd, cwd=root, stdout=f, stderr=subprocess.STDOUT).returncode:
                print(f"ima: the coverage build failed (log: {log})", file=sys.stderr)
                print(log.read_text()[-3000:], file=sys.stderr)
                return False
    return True


def _run_coverage(root: Path, keyword: str | None) -> int:
    """The C and Python tests against build-coverage/ (gcov counters in every program the
    tests run, partitions included), then gcovr's figures per component."""
    build = root / "build-coverage"
    if not _build_coverage(root, build):
        return 1
    code_coverage.reset_counters(build)
    outcomes = [_run_ctest(root, build)]
    # The tests, and the ./ima they call, find the programs in the build tree these name.
    # The tree is built: a test's ./ima must not rebuild it (a second build while counters are
    # written leaves .gcda files gcov refuses as stamped by other objects).
    env = dict(os.environ, IMA_BUILD_DIR=str(build), IMA_PARTITION_PATH=str(build / "partitions"),
               IMA_COVERAGE="1", IMA_SKIP_BUILD="1")
    cmd = pytest_command(sys.executable, paths.tests_dir(), keyword, env)
    outcomes.append(pytest_outcome(subprocess.run(cmd, cwd=root, env=env).returncode))
    gcovr = code_coverage.gcovr_command(sys.executable, root, build)
    if subprocess.run(gcovr, cwd=root, stdout=subprocess.DEVNULL).returncode != 0:
        outcomes.append(Outcome("gcovr", False, f"failed: {' '.join(gcovr)}"))
    else:
        report, figures = code_coverage.write_report(build)
        print(code_coverage.table(figures))
        print(f"ima: coverage per component in {report}; per file in "
              f"{build / code_coverage.FILES_REPORT} and {build / 'coverage-files.txt'}")
    line, code = summary(outcomes)
    print(line)
    return code


def run(args: argparse.Namespace) -> int:
    root = paths.repo_root()
    if args.coverage:
        return _run_coverage(root, args.keyword)
    if args.fuzz_long is not None:
        if args.fuzz_long < 1:
            raise ImaError("--fuzz-long N: at least one input", exit_code=2)
        return _run_fuzz_long(root, args.fuzz_long)
    outcomes = []
    if not args.py_only:
        outcomes.append(_run_ctest(root, paths.build_dir()))
        if not args.no_sanitize:
            outcomes.append(_run_sanitized(root, root / "build-asan"))
    if not args.unit_only:
        outcomes.append(_run_pytest(root, args.keyword))
    line, code = summary(outcomes)
    print(line)
    return code
