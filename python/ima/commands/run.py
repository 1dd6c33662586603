# SPDX-License-Identifier: Apache-2.0
"""`ima run`: runs one ARINC 653 module on the separation kernel emulator and prints its summary."""

from __future__ import annotations

import argparse
import json
import signal
import sys

from ima import ske


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be at least 1: {text}")
    return value


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "run",
        help="run one module on the separation kernel emulator",
        description="Run one ARINC 653 module (XML) on ima-ske and print the schedule summary. "
        "The exit code is ima-ske's: 0 ok, 1 runtime failure, 2 configuration error.",
    )
    parser.add_argument("module", metavar="MODULE.xml", help="ARINC 653 module configuration")
    parser.add_argument(
        "--frames",
        type=positive_int,
        metavar="N",
        help="stop after N major frames (default: until Ctrl-C)",
    )
    parser.add_argument(
        "--realtime",
        action="store_true",
        help="start windows on the monotonic clock instead of emulated time",
    )
    parser.add_argument("--trace", metavar="FILE", help="write trace events (JSON lines) to FILE")
    parser.add_argument("--node", metavar="NAME", help="name of this processor in traces")
    parser.add_argument(
        "--json",
        action="store_true",
        help="print the statistics as JSON instead of the summary table",
    )
    return parser


def show(stats: dict, as_json: bool) -> None:
    if as_json:
        json.dump(stats, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        ske.print_summary(stats)


def signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


def exit_code(returncode: int) -> int:
    """The ima exit code for an ima-ske exit code (a negative one means killed by a signal)."""
    return 128 - returncode if returncode < 0 else returncode


def run(args: argparse.Namespace) -> int:
    try:
        returncode, stats = ske.run_module(
            args.module,
            frames=args.frames,
            realtime=args.realtime,
            trace=args.trace,
            node=args.node,
            quiet=args.json,
        )
    except ske.SkeInterrupted as exc:
        # Show what ran before the interruption, then let it end the process.
        if exc.stats:
            show(exc.stats, args.json)
        raise
    if returncode == ske.EXIT_CONFIG_ERROR:
        return returncode  # ima-ske has said what is wrong, with file and line
    if stats:
        show(stats, args.json)
    if returncode < 0:
        print(f"ima: ima-ske was killed by {signal_name(-returncode)}", file=sys.stderr)
    elif returncode != 0 and not stats:
        print(f"ima: ima-ske failed (exit code {returncode})", file=sys.stderr)
    return exit_code(returncode)
