# SPDX-License-Identifier: Apache-2.0
"""The `ima` command line: parses arguments, dispatches to a subcommand, reports ImaError."""

from __future__ import annotations

import argparse
import os
import signal
import sys
import traceback
from collections.abc import Sequence

from ima import __version__
from ima.commands import bench, campaign, demo, deploy, fdr, fly, launch, mission, run, test, trace
from ima.errors import ImaError

# Registration is explicit: a new subcommand is added here, never discovered by a scan.
COMMANDS = [run, fly, demo, launch, campaign, fdr, trace, test, bench, deploy, mission]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ima",
        description="IMA Testbed: partitioned ARINC 653 avionics on emulated processors.",
    )
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in COMMANDS:
        sub = command.add_parser(subparsers)
        sub.set_defaults(func=command.run, fast_exit=getattr(command, "FAST_EXIT", False))
    return parser


def _die_by_signal(signum: int) -> None:
    """Ends the process by `signum` so a calling shell or script sees the interruption."""
    sys.stdout.flush()
    sys.stderr.flush()
    signal.signal(signum, signal.SIG_DFL)
    os.kill(os.getpid(), signum)
    # Only reached if the signal is blocked; fall back to the shell's convention.
    raise SystemExit(128 + signum)


def main(argv: Sequence[str] | None = None, exit_process: bool = False) -> int:
    """Runs the command; its exit status. With `exit_process` (the process's entry point,
    ima.__main__), a command whose module sets FAST_EXIT ends the process as soon as it is
    done: what it started has ended and what it wrote is closed, so the interpreter's teardown
    (freeing every module and object, some 0.1 s once numpy and the like are loaded) is
    skipped."""
    args = build_parser().parse_args(argv)
    code = _run(args)
    if exit_process and args.fast_exit:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except ValueError:  # closed
                pass
            except BrokenPipeError:  # the reader went away, as in _run()
                code = code or 141
            except OSError:  # what was written is lost (a full disk): as Python says so, 120
                code = code or 120
        os._exit(code)
    return code


def _run(args: argparse.Namespace) -> int:
    try:
        return args.func(args) or 0
    except ImaError as exc:
        if args.debug:
            traceback.print_exc()
        print(f"ima: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except BrokenPipeError:
        # The reader went away (`ima run ... --json | head`): stop quietly, as cat would.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141  # 128 + SIGPIPE
    except KeyboardInterrupt as exc:
        # Not swallowed: the process still ends by the signal, only without a traceback.
        if args.debug:
            raise
        print(file=sys.stderr)
        _die_by_signal(getattr(exc, "signum", signal.SIGINT))
        raise  # not reached
