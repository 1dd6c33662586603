# SPDX-License-Identifier: Apache-2.0
"""`ima bench`: runs a benchmark and prints its measurements."""

from __future__ import annotations

import argparse
from pathlib import Path

from ima.commands.run import positive_int


def _target(targets, name: str, help_: str, duration: int | None = None,
            duration_help: str = "") -> argparse.ArgumentParser:
    """A benchmark's subcommand: --json, and --duration SECONDS when it flies."""
    p = targets.add_parser(name, help=help_)
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    if duration is not None:
        p.add_argument("--duration", type=positive_int, default=duration, metavar="SECONDS",
                       help=f"{duration_help} (default {duration})")
    return p


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench",
        help="run a benchmark (JSON with --json)",
        description="Run a benchmark. Speed and memory targets are measured here, "
        "never asserted in timed tests.",
    )
    targets = parser.add_subparsers(dest="target", metavar="TARGET", required=True)
    ske = _target(targets, "ske", "separation kernel emulator: schedule speed, window switch "
                  "time (floating and pinned to one CPU), jitter")
    ske.add_argument(
        "--frames",
        type=positive_int,
        metavar="N",
        help="major frames per measurement (default: the benchmark's own)",
    )
    _target(targets, "flight", "flight loop: speed-up of a 10-minute ima launch of one node "
            "(floating, pinned to one CPU, one flight per CPU), CPU by process kind, the floor, "
            "CAN bus frames/s, peak memory", 600, "emulated flight time")
    tri = _target(targets, "triplex", "the triplex system: speed-up of a 10-minute ima launch "
                  "of 3 nodes (floating, pinned, one flight per CPU), CPU by process kind, the "
                  "floor, node-to-node DDS latency next to ddsperf's, peak memory", 600,
                  "emulated flight time")
    tri.add_argument("--dds-security", choices=("auth", "sign", "encrypt"), default="sign",
                     metavar="MODE", help="the DDS Security mode the secure latency is measured "
                     "in: auth, sign (the default, as runs have it) or encrypt")
    camp = _target(targets, "campaign", "the campaign runner: runs per hour of 60 s and 300 s "
                   "triplex flights at -j 1 and -j 2, parallel efficiency, runner overhead, peak "
                   "memory")
    camp.add_argument("--runs-60", type=positive_int, default=8, metavar="N",
                      help="runs of 60 s flights per measurement (default 8)")
    camp.add_argument("--runs-300", type=positive_int, default=6, metavar="N",
                      help="runs of 300 s flights per measurement (default 6)")
    tr = _target(targets, "trace", "the recording's cost on a triplex run, ima trace stats on "
                 "10-minute and 1-hour recordings, against python-can's readers", 120,
                 "the flights timed with and without recording")
    tr.add_argument("--pairs", type=positive_int, default=3, metavar="N",
                    help="alternating pairs of flights (default 3)")
    _target(targets, "mission", "the mission manager: its CPU time per cycle (median, p99, "
            "max) against its window, and the speed-up of a one-hour mission in the triplex",
            3600, "the triplex mission's emulated time")
    cmp_ = targets.add_parser(
        "compare", help="a benchmark of this checkout against another checkout (the previous "
        "main), alternating, pinned to one CPU; per-pair ratios and their median")
    cmp_.add_argument("base", type=Path, metavar="CHECKOUT",
                      help="the other checkout, built (e.g. a git worktree of the previous main)")
    cmp_.add_argument("bench", choices=("ske", "flight", "triplex"), help="the benchmark")
    cmp_.add_argument("--pairs", type=positive_int, default=5, metavar="N",
                      help="alternating pairs of runs (default 5)")
    cmp_.add_argument("--cpu", type=int, default=0, metavar="K",
                      help="the CPU every run is pinned to (default 0; -1: not pinned)")
    cmp_.add_argument("--json", action="store_true", help="print the results as JSON")
    return parser


def run(args: argparse.Namespace) -> int:
    if args.target == "compare":
        from ima.bench import compare

        cpu = None if args.cpu < 0 else args.cpu
        return compare.run(args.base, args.bench, args.pairs, cpu, args.json)
    if args.target == "ske":
        from ima.bench import ske

        return ske.run(frames=args.frames, json_out=args.json) or 0
    if args.target == "flight":
        from ima.bench import flight

        return flight.run(json_out=args.json, duration_s=float(args.duration)) or 0
    if args.target == "triplex":
        from ima.bench import triplex

        return triplex.run(json_out=args.json, duration_s=float(args.duration),
                           dds_security=args.dds_security) or 0
    if args.target == "campaign":
        from ima.bench import campaign

        return campaign.run(json_out=args.json, runs_60=args.runs_60, runs_300=args.runs_300)
    if args.target == "mission":
        from ima.bench import mission

        return mission.run(json_out=args.json, duration_s=float(args.duration))
    if args.target == "trace":
        from ima.bench import trace

        return trace.run(json_out=args.json, duration=args.duration, pairs=args.pairs)
    raise AssertionError(f"unhandled bench target {args.target}")  # argparse restricts it
