# SPDX-License-Identifier: Apache-2.0
"""`ima bench`: runs a benchmark and prints its measurements."""

from __future__ import annotations

import argparse
from pathlib import Path

from ima.commands.run import positive_int


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench",
        help="run a benchmark (JSON with --json)",
        description="Run a benchmark. Speed and memory targets are measured here, "
        "never asserted in timed tests.",
    )
    targets = parser.add_subparsers(dest="target", metavar="TARGET", required=True)
    ske = targets.add_parser(
        "ske", help="separation kernel emulator: schedule speed, window switch time, jitter"
    )
    ske.add_argument("--json", action="store_true", help="print the results as JSON")
    ske.add_argument(
        "--frames",
        type=positive_int,
        metavar="N",
        help="major frames per measurement (default: the benchmark's own)",
    )
    fl = targets.add_parser(
        "flight", help="flight loop: speed-up of a 10-minute flight, CAN bus frames/s, peak memory"
    )
    fl.add_argument("--json", action="store_true", help="print the results as JSON")
    fl.add_argument("--duration", type=positive_int, default=600, metavar="SECONDS",
                    help="emulated flight time (default 600)")
    tri = targets.add_parser(
        "triplex", help="the triplex system: speed-up of a 10-minute flight of 3 nodes, "
        "node-to-node DDS latency next to ddsperf's, peak memory")
    tri.add_argument("--json", action="store_true", help="print the results as JSON")
    tri.add_argument("--duration", type=positive_int, default=600, metavar="SECONDS",
                     help="emulated flight time (default 600)")
    tri.add_argument("--dds-security", choices=("auth", "sign", "encrypt"), default="sign",
                     metavar="MODE", help="the DDS Security mode the secure latency is measured "
                     "in: auth, sign (the default, as runs have it) or encrypt")
    camp = targets.add_parser(
        "campaign", help="the campaign runner: runs per hour of 60 s and 300 s triplex "
        "flights at -j 1 and -j 2, parallel efficiency, runner overhead, peak memory")
    camp.add_argument("--json", action="store_true", help="print the results as JSON")
    camp.add_argument("--runs-60", type=positive_int, default=8, metavar="N",
                      help="runs of 60 s flights per measurement (default 8)")
    camp.add_argument("--runs-300", type=positive_int, default=6, metavar="N",
                      help="runs of 300 s flights per measurement (default 6)")
    tr = targets.add_parser(
        "trace", help="the recording's cost on a triplex run, ima trace stats on 10-minute and "
        "1-hour recordings, against python-can's readers")
    tr.add_argument("--json", action="store_true", help="print the results as JSON")
    tr.add_argument("--duration", type=positive_int, default=120, metavar="SECONDS",
                    help="the flights timed with and without recording (default 120)")
    tr.add_argument("--pairs", type=positive_int, default=3, metavar="N",
                    help="alternating pairs of flights (default 3)")
    mis = targets.add_parser(
        "mission", help="the mission manager: its CPU time per cycle (median, p99, max) "
        "against its window, and the speed-up of a one-hour mission in the triplex")
    mis.add_argument("--json", action="store_true", help="print the results as JSON")
    mis.add_argument("--duration", type=positive_int, default=3600, metavar="SECONDS",
                     help="the triplex mission's emulated time (default 3600)")
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
