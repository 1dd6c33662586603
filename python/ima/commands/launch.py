# SPDX-License-Identifier: Apache-2.0
"""`ima launch SYSTEM.yaml`: deploys a system model and flies it: world, CAN bus, and every
node's SKE (with its partitions) and DDS agent, in lockstep; voted flight control. `ima fly`
and `ima demo` are launches of a shipped system through the same options and code."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ima import outdir, provenance
from ima.errors import ImaError
from ima.launch import faults as fault_plan
from ima.launch import judging as judging_mod
from ima.launch import options as launch_options
from ima.launch import report as launch_report
from ima.launch import run as launch_run
from ima.launch import summary as launch_summary
from ima.recording import recorder as recording
from ima.websocket import launcher as live_server


def positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: '{text}'") from None
    if not v > 0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, not '{text}'")
    return v


def _within(text: str, kind, lo, hi, what: str, bad: str):
    """text as `kind` (float or int) within lo..hi; argparse's error otherwise."""
    try:
        v = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what}: '{text}'") from None
    if not lo <= v <= hi:
        raise argparse.ArgumentTypeError(f"{bad}, not '{text}'")
    return v


def wind_kt(text: str) -> float:
    return _within(text, float, 0, 60, "not a number", "wind must be within 0..60 kt")


def _node_at(option: str):
    """The argparse type of a NODE@SECONDS option."""
    def parse(text: str) -> tuple[str, float]:
        try:
            return launch_options.parse_node_at(text, option)
        except ImaError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return parse


def _wrong(text: str) -> tuple[str, str, float, float]:
    try:
        return launch_options.parse_wrong_output(text)
    except ImaError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _replan(text: str) -> tuple[float, Path]:
    """--replan SECONDS:PLAN.yaml."""
    t, sep, path = text.partition(":")
    try:
        t_s = float(t)
    except ValueError:
        t_s = math.nan
    if not sep or not path or not 0 < t_s < math.inf:
        raise argparse.ArgumentTypeError(f"expected SECONDS:PLAN.yaml with SECONDS > 0, not "
                                         f"'{text}'")
    return t_s, Path(path)


def _port(text: str) -> int:
    return _within(text, int, 0, 65535, "not a port number", "a port is 0..65535")


def add_run_arguments(parser: argparse.ArgumentParser, kind: str = "launch") -> None:
    """The options of every run (`ima launch`, `ima fly`, `ima demo`)."""
    parser.add_argument("--duration", type=positive_float, default=600.0, metavar="SECONDS",
                        help="emulated flight time (default 600)")
    parser.add_argument("--seed", type=int, default=1, metavar="N",
                        help="seed of sensor noise and turbulence (default 1)")
    parser.add_argument("--pilot", type=Path, metavar="FILE",
                        help="remote pilot script (default sim/pilots/default.yaml; with "
                        "--mission sim/pilots/fly_mission.yaml)")
    parser.add_argument("--mission", type=Path, metavar="PLAN.yaml",
                        help="a mission plan (config/missions/): the station uplinks it over "
                        "the C2 link and the mission manager flies it; the summary gains each "
                        "leg's accuracy (docs/mission.md)")
    parser.add_argument("--replan", type=_replan, action="append", default=[],
                        metavar="SECONDS:PLAN.yaml",
                        help="uplink another plan at SECONDS, replacing the plan flown "
                        "(repeatable; the summary judges the legs of --mission's plan)")
    parser.add_argument("--turbulence", choices=launch_options.TURBULENCE, default="light",
                        help="MIL-F-8785C turbulence (default light)")
    parser.add_argument("--wind", type=wind_kt, default=10.0, metavar="KT",
                        help="mean wind speed, from 270° (default 10)")
    parser.add_argument("--realtime", action="store_true",
                        help="follow the wall clock instead of running as fast as possible")
    parser.add_argument("--live", action="store_true",
                        help="serve the run while it flies over the Foxglove WebSocket protocol "
                        "on 127.0.0.1 (open ws://127.0.0.1:PORT in Foxglove), at real time "
                        "unless --speed is given (docs/recording.md)")
    parser.add_argument("--live-port", type=_port, default=8765, metavar="PORT",
                        help="--live's port (default 8765; 0: any free port)")
    parser.add_argument("--speed", type=positive_float, metavar="FACTOR",
                        help="fly no faster than FACTOR emulated seconds per wall second, "
                        "still in lockstep (default with --live: 1)")
    parser.add_argument("--run-dir", type=outdir.dir_arg, metavar="DIR",
                        help=f"where the traces go (default runs/{kind}-<date>-<time>-seed<N>)")
    parser.add_argument("--json", action="store_true",
                        help="print the summary as one JSON object on stdout")
    parser.add_argument("--fault", action="append", default=[], metavar="SPEC",
                        help="inject a fault (repeatable), e.g. nav_fcs@node2:memory_violation@60 "
                        "(grammar and classes: docs/fault-injection.md)")
    parser.add_argument("--faults", type=Path, metavar="FILE.yaml",
                        help="inject the faults a YAML file lists (docs/fault-injection.md)")
    parser.add_argument("--no-judge", action="store_true",
                        help="with faults: do not fly the golden run nor judge the run with the "
                        "oracles")
    parser.add_argument("--golden", type=Path, metavar="RUN_DIR",
                        help="with faults: the golden run to judge against (the same run without "
                        "faults, flown before); default: flown into RUN_DIR/golden")
    parser.add_argument("--kill-node", type=_node_at("--kill-node"), action="append", default=[],
                        metavar="NODE@SECONDS",
                        help="stop a whole processor at that emulated time (repeatable), "
                        "e.g. node2@120; the same as --fault NODE:node_crash@SECONDS")
    parser.add_argument("--hang-node", type=_node_at("--hang-node"), action="append", default=[],
                        metavar="NODE@SECONDS",
                        help="freeze a processor's SKE and partitions at that emulated time "
                        "(its DDS agent lives on): a hung node, found by the DDS deadline "
                        "(repeatable); the same as --fault NODE:node_freeze@SECONDS")
    parser.add_argument("--test-wrong-output", type=_wrong, action="append", default=[],
                        metavar="NODE@SECONDS[:AXIS=OFFSET]",
                        help="that replica's actuator command is offset from then on (default "
                        "elev=0.3); the same as --fault NODE:wrong_output@SECONDS:mode=bias,"
                        "axis=AXIS,value=OFFSET")
    parser.add_argument("--test-switch", action="append", default=[], metavar="WHERE:NAME",
                        help=argparse.SUPPRESS)  # test-only: plants violations (docs/campaigns.md)
    parser.add_argument("--dds-security", choices=("off", "auth", "sign", "encrypt"),
                        metavar="MODE",
                        help="DDS Security of the nodes' agents: off, auth (authentication and "
                        "access control), sign (and a MAC on every message), encrypt (and "
                        "encrypted messages); default: the system model's channels.dds.security "
                        "(docs/security.md)")
    parser.add_argument("--no-recording", action="store_true",
                        help="do not make RUN_DIR/run.mcap at the end (docs/recording.md; "
                        "`ima trace recover RUN_DIR` makes it later)")
    parser.add_argument("--netns", action="store_true",
                        help="put each node in its own network namespace joined by a bridge "
                        "(root only), so that a node can really be cut off the network")


# Once the summary is out, the process ends without the interpreter's teardown (ima.cli.main).
FAST_EXIT = True


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "launch",
        help="deploy a system model and fly it on its emulated processors (voted flight control)",
        description="Deploy SYSTEM.yaml (config/systems/) and fly it: the CAN bus, the world "
        "(JSBSim, smart actuators voting over the replicas), and on every node an SKE with the "
        "partition set and, with several nodes, a DDS agent, all in lockstep emulated time (or "
        "--realtime). A live view shows each node and the vote; the summary ends the run.",
    )
    parser.add_argument("system", type=Path, metavar="SYSTEM.yaml", help="the system model")
    add_run_arguments(parser)
    return parser


def faults_from(args: argparse.Namespace) -> list:
    """--fault specs (f1, f2, ... in order), then the --faults file's."""
    from faultinject import grammar

    faults = [grammar.parse(spec, f"f{k}") for k, spec in enumerate(args.fault, start=1)]
    if args.faults is not None:
        faults += grammar.from_yaml_file(args.faults, first=len(faults) + 1)
    return grammar.check_ids(faults, "the run's faults")


def options_from(args: argparse.Namespace, system: Path | None = None,
                 kind: str = "launch") -> launch_options.LaunchOptions:
    return launch_options.LaunchOptions(
        system=system or args.system, duration_s=args.duration, seed=args.seed, pilot=args.pilot,
        mission=args.mission, replan=list(args.replan),
        turbulence=args.turbulence, wind_kt=args.wind, realtime=args.realtime,
        run_dir=args.run_dir, kind=kind, kill=list(args.kill_node), hang=list(args.hang_node),
        wrong_output=list(args.test_wrong_output), netns=args.netns, faults=faults_from(args),
        judge=not args.no_judge, golden=args.golden, test_switches=list(args.test_switch),
        dds_security=args.dds_security, live=args.live, live_port=args.live_port,
        speed=args.speed)


def launch_and_summarise(opts: launch_options.LaunchOptions, json_out: bool,
                         record: bool = True) -> int:
    from rich.console import Console, Group
    from rich.live import Live
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from ima.deploy import load_system
    from ima.launch.live import LiveState

    console = Console(stderr=json_out)
    system = load_system(Path(opts.system))
    nodes = [n.name for n in system.nodes]
    pilot = Path(opts.pilot) if opts.pilot else launch_options.default_pilot(
        opts.mission is not None)
    progress = Progress(TextColumn("[bold]flight[/]"), BarColumn(),
                        TextColumn("{task.completed:>6.0f}/{task.total:.0f} s"),
                        TimeRemainingColumn(), console=console)
    task = progress.add_task("flight", total=opts.duration_s)
    if opts.realtime and opts.speed is not None:
        raise ImaError("--speed paces a lockstep run; --realtime follows the wall clock: "
                       "choose one", exit_code=2)
    if opts.run_dir is None:
        opts.run_dir = launch_options.new_run_dir(opts.kind, opts.seed)
    outdir.usable_dir(Path(opts.run_dir), "--run-dir")
    wanted = fault_plan.requested(opts)
    judging = bool(wanted) and opts.judge
    if judging:
        opts.port_hashes = True  # the data-isolation oracle compares them with the golden run
    stops = {cls: {f.target.node: f.trigger.at_s for f in wanted
                   if f.cls == cls and f.trigger.at_s is not None}
             for cls in ("node_crash", "node_freeze")}
    state = LiveState(Path(opts.run_dir), nodes, stops["node_crash"], hangs=stops["node_freeze"])

    served = None
    if opts.live:
        served = live_server.start(Path(opts.run_dir).resolve(), nodes, opts.live_port)
        console.print(f"live: [bold]{served[1]}[/] (Foxglove: Open connection, Foxglove "
                      f"WebSocket), at {opts.speed or 1:g}x real time")
    # the recording follows the traces while the run flies (on the CPU the lockstep leaves)
    recorder = recording.start(Path(opts.run_dir), nodes) if record else None
    try:
        if not console.is_terminal:
            # nobody watches (a pipe, a file, a campaign, a benchmark): no live view to
            # follow the traces for and draw
            result = launch_run.launch(opts, system=system)
        else:
            with Live(progress, console=console, transient=True, refresh_per_second=4) as live:
                def on_status(st: dict) -> None:
                    state.update(st)
                    progress.update(task, completed=min(st.get("t_s", 0), opts.duration_s))
                    live.update(Group(state.render(), progress))

                result = launch_run.launch(opts, on_status=on_status, system=system)
    except BaseException:
        recording.abandon(recorder, Path(opts.run_dir))
        raise
    finally:
        served_counts = live_server.finish(served[0]) if served is not None else {}
    recording.flown(recorder)  # it reads what is left while we summarise
    summary = launch_summary.summarise(result.run_dir, pilot, opts.duration_s, result.nodes,
                                       result.killed, result.wall_s, plot=True,
                                       hung=result.hung,
                                       fault_targets=launch_summary.fault_targets(result.plan))
    if opts.mission is not None:
        from ima.mission import flown
        from ima.mission import plan as mission_plan

        gone = {**result.killed, **result.hung}
        node = next((n for n in result.nodes if n not in gone), result.nodes[0])
        summary.update(flown.judge(result.run_dir, mission_plan.load(opts.mission), node))
        from ima.mission import track

        try:  # a full disk: the summary says so, the run is not lost
            path = track.write_track(result.run_dir, mission_plan.load(opts.mission), summary)
            summary["track_png"] = str(path)
        except OSError as exc:
            summary["track_png"] = None
            summary["track_error"] = f"{Path(result.run_dir) / 'track.png'}: {exc.strerror}"
    summary["returncodes"] = result.returncodes
    # Ctrl-C (or SIGTERM): the run ended early, at the last emulated time the world recorded
    summary["interrupted"] = bool(result.interrupted)
    summary["interrupted_at_s"] = summary.get("flown_s") if result.interrupted else None
    summary["dds_domain"] = result.domain
    summary["provenance"] = provenance.provenance()
    if served is not None:
        summary["live_url"] = served[1]
        summary.update(served_counts)
    launch_summary.write(result.run_dir, summary)
    if result.plan is not None:
        summary["faults"] = [{"id": f.fid, "spec": f.spec(), "class": f.cls,
                              "t_s": f.trigger.at_s, "applied": None} for f in result.plan.faults]
        if judging and not result.interrupted:
            with console.status("judging the run: the golden run, then the oracles"):
                summary.update(judging_mod.judge(opts, result, system))
        launch_summary.write(result.run_dir, summary)
    if record:
        summary.update(recording.finish(recorder))
        launch_summary.write(result.run_dir, summary)
    failed = {k: v for k, v in result.returncodes.items()
              if v not in (0, None) and k.split("/")[0] not in {**result.killed, **result.hung}}
    if json_out:
        json.dump(summary, sys.stdout)
        sys.stdout.write("\n")
    else:
        launch_report.print_summary(summary, console)
    if result.interrupted:
        raise KeyboardInterrupt
    if failed:
        raise ImaError(f"processes failed: {failed} (logs in {result.run_dir})")
    return 0


def run(args: argparse.Namespace) -> int:
    return launch_and_summarise(options_from(args), args.json, not args.no_recording)
