# SPDX-License-Identifier: Apache-2.0
"""`ima fdr RUN_DIR NODE`: decodes a node's flight data recording (RUN_DIR/NODE.fdr): the
summary (records, gaps, torn records, time span), every record as CSV or JSON lines, and a
plot of the main channels."""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

from ima.errors import ImaError


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "fdr",
        help="decode a node's flight data recording (gaps, torn records, CSV/JSON, plot)",
        description="Decode RUN_DIR/NODE.fdr, the recording of NODE's flight data recorder "
        "partition: print its summary (records, gaps in the frames, torn records skipped, the "
        "time span); --csv or --jsonl write every frame (or HM decision) out; --plot draws the "
        "main channels (docs/flight-data-recorder.md).",
    )
    parser.add_argument("run_dir", metavar="RUN_DIR", type=Path, help="a run directory")
    parser.add_argument("node", metavar="NODE", help="the node, e.g. node1")
    parser.add_argument("--json", action="store_true", help="the summary as one JSON object")
    parser.add_argument("--csv", metavar="FILE", type=Path,
                        help="the frames as CSV (one row per frame; '-' for stdout)")
    parser.add_argument("--jsonl", metavar="FILE", type=Path,
                        help="every record as JSON lines ('-' for stdout)")
    parser.add_argument("--plot", metavar="PNG", type=Path, help="plot the main channels")
    return parser


def _open(path: Path):
    return sys.stdout if str(path) == "-" else open(path, "w", encoding="utf-8", newline="")  # noqa: SIM115


def _frame_row(f: dict) -> dict:
    row = {"frame": f["frame"], "t_s": f["t_ns"] / 1e9, "seq": f["seq"]}
    for part in ("nav", "status", "mission"):
        for k, v in (f[part] or {}).items():
            if k != "t_ns":
                row[f"{part}.{k}"] = v
    return row


def run(args: argparse.Namespace) -> int:
    from ima.fdr import records

    path = args.run_dir / f"{args.node}.fdr"
    if not path.is_file():
        found = sorted(p.stem for p in args.run_dir.glob("*.fdr")) if args.run_dir.is_dir() \
            else []
        raise ImaError(f"{path}: no recording" + (f" (recordings here: {', '.join(found)})"
                                                   if found else ""), exit_code=2)
    try:
        rec = records.read(path)
    except OSError as exc:
        raise ImaError(f"{path}: cannot read: {exc.strerror}") from exc
    summary = rec.summary()
    if args.csv:
        rows = [_frame_row(f) for f in rec.frames]
        cols = list(dict.fromkeys(k for r in rows for k in r))
        out = _open(args.csv)
        w = csv.DictWriter(out, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
        if out is not sys.stdout:
            out.close()
    if args.jsonl:
        out = _open(args.jsonl)
        allrec = sorted([("start", r) for r in rec.starts] + [("frame", r) for r in rec.frames]
                        + [("hm", r) for r in rec.hm], key=lambda kr: kr[1]["offset"])
        for kind, r in allrec:
            out.write(json.dumps({"kind": kind, **r}) + "\n")
        if out is not sys.stdout:
            out.close()
    if args.plot:
        from ima.fdr import plot

        plot.plot(rec, args.plot, f"{args.node}: {path}")
        summary["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(summary))
    elif not (args.csv and str(args.csv) == "-") and not (args.jsonl and str(args.jsonl) == "-"):
        span = "-" if summary["t_first_s"] is None else \
            f"{summary['t_first_s']:.2f} .. {summary['t_last_s']:.2f} s"
        print(f"{path}: {summary['records']} records ({summary['frames']} frames, "
              f"{summary['hm_events']} HM decisions, {summary['starts']} starts), "
              f"{summary['gaps']} gaps ({summary['missing_frames']} frames missing), "
              f"{summary['torn']} torn records, time {span}")
    return 0
