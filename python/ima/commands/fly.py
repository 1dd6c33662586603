# SPDX-License-Identifier: Apache-2.0
"""`ima fly`: one emulated processor flies the aircraft (world + CAN bus + node) and the
flight is judged from the world's truth trace."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ima.errors import ImaError
from ima.flight import run as flight
from ima.flight import summary as flight_summary


def positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: '{text}'") from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, not '{text}'")
    return v


def wind_kt(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: '{text}'") from None
    if not 0 <= v <= 60:
        raise argparse.ArgumentTypeError(f"wind must be within 0..60 kt, not '{text}'")
    return v


def add_flight_arguments(parser: argparse.ArgumentParser, duration: float = 600.0) -> None:
    parser.add_argument("--duration", type=positive_float, default=duration, metavar="SECONDS",
                        help=f"emulated flight time (default {duration:g})")
    parser.add_argument("--seed", type=int, default=1, metavar="N",
                        help="seed of sensor noise and turbulence (default 1)")
    parser.add_argument("--pilot", type=Path, metavar="FILE",
                        help="remote pilot script (default sim/pilots/default.yaml)")
    parser.add_argument("--turbulence", choices=flight.TURBULENCE, default="light",
                        help="MIL-F-8785C turbulence (default light)")
    parser.add_argument("--wind", type=wind_kt, default=10.0, metavar="KT",
                        help="mean wind speed, from 270° (default 10)")
    parser.add_argument("--realtime", action="store_true",
                        help="follow the wall clock instead of running as fast as possible")
    parser.add_argument("--run-dir", type=Path, metavar="DIR",
                        help="where the traces go (default runs/fly-<date>-<time>-seed<N>)")
    parser.add_argument("--json", action="store_true",
                        help="print the summary as one JSON object on stdout")


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "fly",
        help="fly the aircraft with one emulated processor (world + CAN bus + node)",
        description="Fly the c172p stand-in airframe in JSBSim with one ARINC 653 processor "
        "(io + nav_fcs partitions) over the virtual CAN bus, in lockstep emulated time, and "
        "judge the flight from the world's truth trace.",
    )
    add_flight_arguments(parser)
    return parser


def options_from(args: argparse.Namespace) -> flight.FlightOptions:
    return flight.FlightOptions(duration_s=args.duration, seed=args.seed, pilot=args.pilot,
                                turbulence=args.turbulence, wind_kt=args.wind,
                                realtime=args.realtime, run_dir=args.run_dir)


def fly_and_summarise(opts: flight.FlightOptions, json_out: bool) -> int:
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    console = Console(stderr=json_out)
    pilot = Path(opts.pilot) if opts.pilot else flight.default_pilot()
    with Progress(
        TextColumn("[bold]flight[/]"), BarColumn(), TextColumn("{task.completed:>6.0f}/{task.total:.0f} s"),
        TextColumn("{task.description}"), TimeRemainingColumn(), console=console, transient=True,
    ) as progress:
        task = progress.add_task("starting", total=opts.duration_s)

        def on_status(st: dict) -> None:
            desc = (f"{st.get('mode') or '-':>10}  {st.get('alt_ft', 0):6.0f} ft  "
                    f"{st.get('airspeed_kt', 0):5.1f} kt  {st.get('heading_deg', 0):5.1f}°")
            progress.update(task, completed=min(st.get("t_s", 0), opts.duration_s), description=desc)

        result = flight.fly(opts, on_status=on_status)
    summary = flight_summary.summarise(result.run_dir, pilot, opts.duration_s, result.wall_s,
                                       nodes=opts.nodes, plot=True)
    summary["returncodes"] = result.returncodes
    failed = {k: v for k, v in result.returncodes.items() if v not in (0, None)}
    return report(summary, failed, result.run_dir, result.interrupted, json_out, console,
                  print_summary)


def report(summary: dict, failed: dict, run_dir: Path, interrupted: bool, json_out: bool,
           console, printer) -> int:
    """Ends a run: the summary (JSON on stdout, or printed), then Ctrl-C or a failure."""
    if json_out:
        json.dump(summary, sys.stdout)
        sys.stdout.write("\n")
    else:
        printer(summary, console)
    if interrupted:
        raise KeyboardInterrupt
    if failed:
        raise ImaError(f"processes failed: {failed} (logs in {run_dir})")
    return 0


def _fmt(v, unit: str, d: int = 1) -> str:
    return "-" if v is None else f"{v:.{d}f} {unit}"


def print_summary(s: dict, console) -> None:
    from rich.table import Table

    console.rule(f"Flight summary — {s['run_dir']}")
    state = "[red]CRASHED[/]" if s["crashed"] else "[green]flying[/]"
    console.print(f"Flown {s['flown_s']:.0f} s emulated in {s.get('wall_s', 0):.1f} s wall "
                  f"(×{s.get('speedup') or 0:.0f}); aircraft {state}")
    console.print("Tracking error, judged on the truth over the hold segments:")
    t = Table(show_edge=False)
    for col in ("", "max |error|", "RMS"):
        t.add_column(col, justify="right")
    t.add_row("altitude", _fmt(s["alt_err_ft_max"], "ft"), _fmt(s["alt_err_ft_rms"], "ft"))
    t.add_row("airspeed", _fmt(s["airspeed_err_kt_max"], "kt"), _fmt(s["airspeed_err_kt_rms"], "kt"))
    t.add_row("heading", _fmt(s["heading_err_deg_max"], "°"), _fmt(s["heading_err_deg_rms"], "°"))
    console.print(t)
    segs = ", ".join(f"{g['t0_s']:.0f}–{g['t1_s']:.0f} s" for g in s["hold_segments"]) or "none"
    console.print(f"Hold segments judged: {segs}; max bank {s['bank_deg_max']:.1f}°")
    modes = " → ".join(f"{m['mode']}@{m['t_s']:.0f}s"
                       + (f" ({m['fallback']})" if m["fallback"] not in (None, "NONE") else "")
                       for m in s["mode_changes"]) or "none reported"
    console.print(f"Flight-control modes (downlink): {modes}")
    load = s.get("bus_load")
    console.print(f"CAN bus: {s.get('can_frames') or 0} frames, load "
                  f"{(load or 0) * 100:.1f} % (max 1 s: {(s.get('bus_load_max_1s') or 0) * 100:.1f} %), "
                  f"error frames {s.get('can_error_frames') or 0}")
    console.print(f"Health-monitor events: {s['hm_events']}")
    if s.get("plot"):
        console.print(f"Plot: {s['plot']}")
    for ev in s["hm_event_list"][:5]:
        console.print(f"  {ev['t_ns'] / 1e9:9.3f} s {ev['node']}/{ev.get('partition')}: "
                      f"{ev.get('error')} → {ev.get('action')}", markup=False)


def run(args: argparse.Namespace) -> int:
    return fly_and_summarise(options_from(args), args.json)
