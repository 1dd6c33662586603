# SPDX-License-Identifier: Apache-2.0
"""`ima demo`: runs the three-partition example module and prints its schedule summary."""

from __future__ import annotations

import argparse

from ima import paths, ske
from ima.commands.run import exit_code, positive_int
from ima.errors import ImaError

EXAMPLE = "three_partitions.xml"
DEFAULT_FRAMES = 200


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo",
        help="run the example module and print the schedule summary",
        description=f"Run config/examples/{EXAMPLE} (three partitions on one emulated "
        "ARINC 653 processor) in emulated time and print the schedule summary.",
    )
    parser.add_argument(
        "--frames",
        type=positive_int,
        default=DEFAULT_FRAMES,
        metavar="N",
        help=f"major frames to run (default {DEFAULT_FRAMES})",
    )
    return parser


def run(args: argparse.Namespace) -> int:
    from rich.console import Console

    module = paths.examples_dir() / EXAMPLE
    if not module.is_file():
        raise ImaError(f"example module not found: {module}")
    console = Console()
    console.rule(
        f"IMA Testbed demo: {module.relative_to(paths.repo_root())}, "
        f"{args.frames} major frames, emulated time"
    )
    try:
        returncode, stats = ske.run_module(module, frames=args.frames)
    except ske.SkeInterrupted as exc:
        if exc.stats:
            ske.print_summary(exc.stats, console)
        raise
    if stats:
        ske.print_summary(stats, console)
    elif returncode != ske.EXIT_CONFIG_ERROR:
        raise ImaError(f"ima-ske wrote no statistics (exit code {returncode})")
    return exit_code(returncode)
