# SPDX-License-Identifier: Apache-2.0
"""`ima launch SYSTEM.yaml`: deploys a system model and flies it: world, CAN bus, and every
node's SKE (with its partitions) and DDS agent, in lockstep; voted flight control."""

from __future__ import annotations

import argparse
from pathlib import Path

from ima.commands import fly
from ima.errors import ImaError
from ima.flight import run as flight
from ima.launch import run as launch_run
from ima.launch import summary as launch_summary


def _node_at(option: str):
    """The argparse type of a NODE@SECONDS option."""
    def parse(text: str) -> tuple[str, float]:
        try:
            return launch_run.parse_kill(text, option)
        except ImaError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return parse


def _wrong(text: str) -> tuple[str, str, float, float]:
    try:
        return launch_run.parse_wrong_output(text)
    except ImaError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_launch_arguments(parser: argparse.ArgumentParser) -> None:
    fly.add_flight_arguments(parser)
    parser.add_argument("--kill-node", type=_node_at("--kill-node"), action="append", default=[], metavar="NODE@SECONDS",
                        help="stop a whole processor at that emulated time (repeatable), "
                        "e.g. node2@120")
    parser.add_argument("--hang-node", type=_node_at("--hang-node"), action="append", default=[],
                        metavar="NODE@SECONDS",
                        help="freeze a processor's SKE and partitions at that emulated time "
                        "(its DDS agent lives on): a hung node, found by the DDS deadline "
                        "(repeatable)")
    parser.add_argument("--test-wrong-output", type=_wrong, action="append", default=[],
                        metavar="NODE@SECONDS[:AXIS=OFFSET]",
                        help="test switch: that replica's actuator command is offset from then "
                        "on (default elev=0.3); the voter must vote it out")
    parser.add_argument("--netns", action="store_true",
                        help="put each node in its own network namespace joined by a bridge "
                        "(root only), so that a node can really be cut off the network")


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "launch",
        help="deploy a system model and fly it on its emulated processors (voted flight control)",
        description="Deploy SYSTEM.yaml (config/systems/) and fly it: the CAN bus, the world "
        "(JSBSim, smart actuators voting over the replicas), and on every node an SKE with the "
        "partition set and a DDS agent, all in lockstep emulated time (or --realtime). A live "
        "view shows each node and the vote; the summary ends the run.",
    )
    parser.add_argument("system", type=Path, metavar="SYSTEM.yaml", help="the system model")
    add_launch_arguments(parser)
    return parser


def options_from(args: argparse.Namespace) -> launch_run.LaunchOptions:
    return launch_run.LaunchOptions(
        system=args.system, duration_s=args.duration, seed=args.seed, pilot=args.pilot,
        turbulence=args.turbulence, wind_kt=args.wind, realtime=args.realtime,
        run_dir=args.run_dir, kill=list(args.kill_node), hang=list(args.hang_node),
        wrong_output=list(args.test_wrong_output),
        netns=args.netns)


def launch_and_summarise(opts: launch_run.LaunchOptions, json_out: bool) -> int:
    from rich.console import Console, Group
    from rich.live import Live
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from ima.deploy import load_system
    from ima.launch.live import LiveState

    console = Console(stderr=json_out)
    system = load_system(Path(opts.system))
    nodes = [n.name for n in system.nodes]
    pilot = Path(opts.pilot) if opts.pilot else flight.default_pilot()
    progress = Progress(TextColumn("[bold]flight[/]"), BarColumn(),
                        TextColumn("{task.completed:>6.0f}/{task.total:.0f} s"),
                        TimeRemainingColumn(), console=console)
    task = progress.add_task("flight", total=opts.duration_s)
    holder: dict = {}

    with Live(progress, console=console, transient=True, refresh_per_second=4) as live:
        def on_status(st: dict) -> None:
            state = holder.get("state")
            if state is None:
                run_dir = holder.get("run_dir")
                if run_dir is None:
                    return
                state = holder["state"] = LiveState(run_dir, nodes, dict(opts.kill),
                                                    hangs=dict(opts.hang))
            state.update(st)
            progress.update(task, completed=min(st.get("t_s", 0), opts.duration_s))
            live.update(Group(state.render(), progress))

        if opts.run_dir is None:
            opts.run_dir = flight.new_run_dir("launch", opts.seed)
        holder["run_dir"] = Path(opts.run_dir)
        result = launch_run.launch(opts, on_status=on_status)
    summary = launch_summary.summarise(result.run_dir, pilot, opts.duration_s, result.nodes,
                                       result.killed, result.wall_s, plot=True,
                                       hung=result.hung)
    summary["returncodes"] = result.returncodes
    summary["dds_domain"] = result.domain
    failed = {k: v for k, v in result.returncodes.items()
              if v not in (0, None) and k.split("/")[0] not in {**result.killed, **result.hung}}
    return fly.report(summary, failed, result.run_dir, result.interrupted, json_out, console,
                      print_summary)


def print_summary(s: dict, console) -> None:
    fly.print_summary(s, console)
    killed = ", ".join([f"{k['node']}@{k['t_s']:g}s (killed)" for k in s["killed"]]
                       + [f"{k['node']}@{k['t_s']:g}s (hung)" for k in s.get("hung", [])]) or "none"
    console.print(f"Nodes: {', '.join(s['nodes'])}; stopped on purpose: {killed}")
    vo = ", ".join(f"{v['node']}@{v['t_s']:.3f}s ({v['reason']})" for v in s["voted_out"]) or "none"
    console.print(f"Voted out by the actuators: {vo}; final vote {s.get('vote_status') or '-'}")
    agreed = "agreed" if s.get("membership_agreed") else "[red]NOT agreed[/]"
    console.print(f"Membership ({agreed}): {', '.join(s.get('membership') or []) or '-'}")
    for ev in s.get("membership_events", [])[:6]:
        console.print(f"  {ev['t_s']:9.3f} s {ev['node']}: {','.join(ev['members'])}")
    for ev in s.get("monitor_reports", [])[:6]:
        console.print(f"  {ev['t_s']:9.3f} s {ev['node']} monitor: {ev['text']}", markup=False)


def run(args: argparse.Namespace) -> int:
    return launch_and_summarise(options_from(args), args.json)
