# SPDX-License-Identifier: Apache-2.0
"""`ima demo`: runs the three-partition example module and prints its schedule summary."""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

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
    console.rule(f"IMA Testbed demo: {module.name}, {args.frames} major frames")
    with tempfile.TemporaryDirectory(prefix="ima-demo-") as tmp:
        trace = Path(tmp) / "trace.jsonl"
        try:
            returncode, stats = ske.run_module(module, frames=args.frames, trace=trace)
        except ske.SkeInterrupted as exc:
            if exc.stats:
                ske.print_summary(exc.stats, console)
            raise
        reports = last_reports(trace)
    if stats:
        ske.print_summary(stats, console)
    elif returncode != ske.EXIT_CONFIG_ERROR:
        raise ImaError(f"ima-ske wrote no statistics (exit code {returncode})")
    if reports:
        console.print("What the partitions last reported (REPORT_APPLICATION_MESSAGE):")
        for src, (t_ns, text) in reports.items():
            console.print(f"  {t_ns / 1e9:8.3f} s  {src:10} {text}", markup=False, highlight=False)
    return exit_code(returncode)


def last_reports(trace: Path) -> dict[str, tuple[int, str]]:
    """The last application message of each partition in a trace: {partition: (t_ns, text)}."""
    reports: dict[str, tuple[int, str]] = {}
    if not trace.exists():
        return reports
    with trace.open() as f:
        for line in f:
            if '"app_message"' not in line:
                continue
            event = json.loads(line)
            if event.get("kind") == "app_message":
                reports[event["src"]] = (event["t_ns"], event.get("text", ""))
    return reports
