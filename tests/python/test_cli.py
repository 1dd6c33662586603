# SPDX-License-Identifier: Apache-2.0
"""Tests of the ima command line: the documented commands parse, errors are one line."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap

import pytest

from ima import cli
from ima.commands import bench, demo, fly, run, test
from ima.errors import ImaError


@pytest.mark.parametrize(
    ("argv", "func", "expected"),
    [
        (["demo"], demo.run, {"duration": 1750.0, "seed": 1, "turbulence": "light", "wind": 10.0}),
        (["demo", "--duration", "60", "--seed", "3"], demo.run, {"duration": 60.0, "seed": 3}),
        (
            ["fly", "--duration", "600", "--seed", "7", "--json"],
            fly.run,
            {"duration": 600.0, "seed": 7, "json": True, "realtime": False, "pilot": None},
        ),
        (
            ["fly", "--turbulence", "none", "--wind", "0", "--realtime"],
            fly.run,
            {"turbulence": "none", "wind": 0.0, "realtime": True},
        ),
        (["bench", "flight", "--json"], bench.run, {"target": "flight", "json": True}),
        (
            ["run", "m.xml"],
            run.run,
            {
                "module": "m.xml",
                "frames": None,
                "realtime": False,
                "trace": None,
                "node": None,
                "json": False,
            },
        ),
        (
            [
                "run",
                "m.xml",
                "--frames",
                "5",
                "--realtime",
                "--trace",
                "t.jsonl",
                "--node",
                "n2",
                "--json",
            ],
            run.run,
            {
                "module": "m.xml",
                "frames": 5,
                "realtime": True,
                "trace": "t.jsonl",
                "node": "n2",
                "json": True,
            },
        ),
        (["test"], test.run, {"keyword": None, "unit_only": False, "py_only": False}),
        (
            ["test", "-k", "sampling and not slow", "--py-only"],
            test.run,
            {"keyword": "sampling and not slow", "py_only": True},
        ),
        (["test", "--unit-only"], test.run, {"unit_only": True}),
        (["bench", "ske"], bench.run, {"target": "ske", "json": False, "frames": None}),
        (
            ["bench", "ske", "--json", "--frames", "1000"],
            bench.run,
            {"target": "ske", "json": True, "frames": 1000},
        ),
        (["--debug", "demo"], demo.run, {"debug": True}),
    ],
)
def test_documented_commands_parse(argv, func, expected):
    args = cli.build_parser().parse_args(argv)
    assert args.func is func
    for name, value in expected.items():
        assert getattr(args, name) == value


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["fly", "--duration", "0"],
        ["fly", "--duration", "nan"],
        ["fly", "--turbulence", "heavy"],
        ["fly", "--wind", "-3"],
        ["fly", "--seed", "x"],
        ["run"],
        ["run", "m.xml", "--frames", "0"],
        ["run", "m.xml", "--frames", "ten"],
        ["test", "--unit-only", "--py-only"],
        ["bench"],
        ["bench", "canbus"],
    ],
)
def test_bad_command_lines_are_usage_errors(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.build_parser().parse_args(argv)
    assert exc.value.code == 2
    assert "usage: ima" in capsys.readouterr().err


def test_every_registered_command_has_the_subcommand_interface():
    for module in cli.COMMANDS:
        assert callable(module.add_parser) and callable(module.run), module.__name__


def _failing(message, exit_code=1):
    def run(args):
        raise ImaError(message, exit_code=exit_code)

    return run


def test_ima_error_is_one_line_without_traceback(monkeypatch, capsys):
    monkeypatch.setattr(demo, "run", _failing("example module not found: x.xml"))
    assert cli.main(["demo"]) == 1
    captured = capsys.readouterr()
    assert captured.err == "ima: error: example module not found: x.xml\n"
    assert captured.out == ""


def test_ima_error_exit_code_is_kept(monkeypatch, capsys):
    monkeypatch.setattr(demo, "run", _failing("m.xml: no such module", exit_code=2))
    assert cli.main(["demo"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_debug_shows_the_traceback(monkeypatch, capsys):
    monkeypatch.setattr(demo, "run", _failing("boom"))
    assert cli.main(["--debug", "demo"]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err
    assert err.rstrip().endswith("ima: error: boom")


def test_other_exceptions_are_not_caught(monkeypatch):
    def broken(args):
        raise ValueError("a bug")

    monkeypatch.setattr(demo, "run", broken)
    with pytest.raises(ValueError):
        cli.main(["demo"])


def test_bench_ske_error_is_one_line(capsys, monkeypatch):
    from ima.bench import ske as bench_ske
    from ima.errors import ImaError

    def broken(frames=None, progress=None):
        raise ImaError("ima-ske failed on trivial.xml (exit code 1)")

    monkeypatch.setattr(bench_ske, "measure", broken)
    assert cli.main(["bench", "ske", "--json"]) == 1
    assert capsys.readouterr().err.endswith("ima: error: ima-ske failed on trivial.xml (exit code 1)\n")


def test_bench_targets_are_judged_in_the_right_direction():
    from ima.bench.ske import _meets

    assert _meets(19.9, "<=", 20.0) and not _meets(20.1, "<=", 20.0)
    assert _meets(5000.0, ">=", 5000.0) and not _meets(4999.0, ">=", 5000.0)
    assert _meets(None, "<=", 1.0) is None


def test_ctrl_c_ends_the_process_by_sigint_without_traceback():
    # In a child process: the CLI must die by SIGINT, so the caller sees the interruption.
    script = textwrap.dedent(
        """
        from ima import cli
        from ima.commands import demo
        def interrupted(args):
            raise KeyboardInterrupt
        demo.run = interrupted
        raise SystemExit(cli.main(["demo"]))
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=30
    )
    assert done.returncode == -signal.SIGINT
    assert "Traceback" not in done.stderr
