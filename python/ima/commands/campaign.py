# SPDX-License-Identifier: Apache-2.0
"""`ima campaign CAMPAIGN.yaml`: runs a fault campaign (golden runs, every run judged by the
oracles, results.jsonl, report.json/html, junit.xml); `ima campaign rerun DIR RUN_ID` flies
one run of it again, exactly, keeping its run directory."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from ima import outdir, paths
from ima.errors import ImaError


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "campaign",
        help="run a fault campaign and write its report (ima campaign rerun DIR RUN_ID: one "
        "run again)",
        description="Run every fault of CAMPAIGN.yaml (config/campaigns/) on its system and "
        "workloads, each against its golden run, judged by the oracles; write "
        "DIR/results.jsonl (a line per run), DIR/report.json, report.html and junit.xml. "
        "`ima campaign rerun DIR RUN_ID` flies one run of a campaign folder again, exactly, "
        "into DIR/rerun/RUN_ID (docs/campaigns.md).",
    )
    parser.add_argument("campaign", metavar="CAMPAIGN.yaml|rerun",
                        help="the campaign file, or `rerun`")
    parser.add_argument("rest", nargs="*", metavar="DIR RUN_ID", help="with rerun")
    parser.add_argument("--out", type=outdir.dir_arg, metavar="DIR",
                        help="the campaign folder (default campaigns/NAME-<date>-<time>)")
    parser.add_argument("-j", "--jobs", type=int, default=None, metavar="N",
                        help="flights at once, one per CPU (default: the CPUs this process "
                        "may use)")
    parser.add_argument("--resume", action="store_true",
                        help="go on with the campaign folder --out: runs already in its "
                        "results.jsonl are skipped")
    parser.add_argument("--keep-all", action="store_true",
                        help="keep every run directory (default: only the failing runs')")
    parser.add_argument("--executor", choices=("local", "dask"), default="local",
                        help="local: processes of this machine; dask: a Dask distributed "
                        "cluster (--scheduler, else a LocalCluster on loopback)")
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                        help="the Dask scheduler (its workers have the project checked out "
                        "and built at the same path)")
    parser.add_argument("--json", action="store_true", help="print report.json on stdout")
    parser.add_argument("--test-switch", action="append", default=[], help=argparse.SUPPRESS)
    return parser


def _jobs(n: int | None) -> int:
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    if n is not None and n < 1:
        raise ImaError("-j must be at least 1", exit_code=2)
    return n or cpus or 1


class _Progress:
    """The live progress bar: goldens, then runs with ETA and counts by outcome. Into a log
    (stderr not a terminal), one line per golden run and per run instead."""

    def __init__(self, console) -> None:
        from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

        self.console = console
        self.live = console.is_terminal
        self.p = Progress(TextColumn("[bold]{task.description}"), BarColumn(),
                          TextColumn("{task.completed}/{task.total}"), TimeRemainingColumn(),
                          TextColumn("{task.fields[counts]}"), console=console, transient=True)
        self.golden = self.runs = None
        self.totals = [0, 0]  # golden runs, runs
        self.finished = [0, 0]
        self.runs_t0: float | None = None  # when the runs began (the ETA counts from there)

    def start(self, goldens: int, runs: int, done: int) -> None:
        self.totals = [goldens, runs]
        if self.live:
            self.p.start()
        self.golden = self.p.add_task("golden runs", total=goldens, counts="")
        self.runs = self.p.add_task("runs", total=runs, counts=f"({done} done before)"
                                    if done else "")

    def golden_done(self) -> None:
        self.p.advance(self.golden)
        self.finished[0] += 1
        if not self.live:
            self.console.print(f"golden run {self.finished[0]}/{self.totals[0]} flown",
                               highlight=False)

    def run_done(self, record: dict, counts, elapsed: float) -> None:
        text = "  ".join(f"{k.replace('_', ' ')} {v}" for k, v in sorted(counts.items()))
        self.p.update(self.runs, advance=1, counts=text)
        self.finished[1] += 1
        now = time.monotonic()
        if self.runs_t0 is None:
            self.runs_t0 = now
        if not self.live:
            n, total = self.finished[1], self.totals[1]
            # The pace of the runs since the first ended (golden runs take longer).
            pace = (now - self.runs_t0) / (n - 1) if n > 1 else elapsed
            eta = pace * (total - n)
            m = record["measures"]
            bad = f", VIOLATED {', '.join(m['oracle_violations'])}" \
                if m["oracle_violations"] else ""
            self.console.print(f"[{n}/{total}] {record['run_id']}: {m['outcome']}{bad} "
                               f"({elapsed:.0f} s, about {eta:.0f} s left)", highlight=False,
                               soft_wrap=True)

    def stop(self) -> None:
        if self.live:
            self.p.stop()


def _rerun(args: argparse.Namespace) -> int:
    from ima.campaign import job

    if len(args.rest) != 2:
        raise ImaError("usage: ima campaign rerun DIR RUN_ID", exit_code=2)
    out, run_id = Path(args.rest[0]), args.rest[1]
    try:
        planned = json.loads((out / "campaign.json").read_text())
    except (OSError, ValueError) as exc:
        raise ImaError(f"{out}: not a campaign folder (campaign.json: {exc})") from exc
    run = next((r for r in planned["runs"] if r["run_id"] == run_id), None)
    if run is None:
        raise ImaError(f"{out}: no run '{run_id}'", exit_code=2)
    from ima.campaign import runner, spec

    c = spec.load(out / "campaign.yaml")
    data = runner.campaign_data(c, runner.RunnerOptions(out=out, jobs=1, keep_all=True,
                                                        argv=tuple(sys.argv)))
    rdata = dict(data, dir=str(out.resolve()))
    runner.fly_golden(rdata, data["golden_of"][run_id], run)
    again = out / "rerun" / run_id  # the campaign's own run directory, if kept, stays
    record = job.run_one(dict(rdata, keep_all=True), run, run_dir=again)
    print(json.dumps(record) if args.json else
          f"{run_id}: outcome {record['measures']['outcome']}, oracle violations "
          f"{record['measures']['oracle_violations'] or 'none'}; run directory {again}")
    return 0


def run(args: argparse.Namespace) -> int:
    from rich.console import Console

    from ima.campaign import report, runner, spec

    if args.campaign == "rerun":
        return _rerun(args)
    if args.rest:
        raise ImaError(f"unexpected arguments: {' '.join(args.rest)}", exit_code=2)
    c = spec.load(Path(args.campaign))
    out = args.out or paths.repo_root() / "campaigns" / \
        f"{c.name}-{time.strftime('%Y%m%d-%H%M%S')}"
    outdir.usable_dir(out, "--out")
    opts = runner.RunnerOptions(out=out, jobs=_jobs(args.jobs), resume=args.resume,
                                keep_all=args.keep_all, executor=args.executor,
                                scheduler=args.scheduler, test_switches=tuple(args.test_switch),
                                argv=tuple(sys.argv))
    console = Console(stderr=True)
    console.print(f"campaign {c.name}: {len(c.runs)} runs, {opts.jobs} at once "
                  f"({opts.executor}), into {out}")
    progress = _Progress(console)
    try:
        records = runner.run(c, opts, progress)
    finally:
        if progress.golden is not None:
            progress.stop()
    rep = report.build(c.name, records, len(c.runs), list(sys.argv))
    written = report.write(out, rep, records)
    if args.json:
        print(json.dumps(rep))
    else:
        term = Console()
        if not term.is_terminal:  # a log file: wide enough for the table on one line a class
            term = Console(width=140)
        report.print_summary(rep, term)
        term.print("Report: " + ", ".join(str(p) for p in written))
    # as junit.xml: a run is a failure when an oracle is violated, or when an undetected
    # hazardous outcome falls outside the catalogue's known limits
    return 1 if rep["oracle_violations"] or rep["undetected_hazardous"] else 0
