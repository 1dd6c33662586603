# SPDX-License-Identifier: Apache-2.0
"""`ima demo`: launches the triplex system (config/systems/rpas_triplex.yaml: three emulated
processors, voted flight control) on the default 10-minute mission and prints the summary."""

from __future__ import annotations

import argparse

from ima.commands import launch
from ima.launch.options import system_path


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo",
        help="launch the triplex on the default 10-minute autopilot mission and print the summary",
        description="Launch config/systems/rpas_triplex.yaml (three ARINC 653 processors, each "
        "with the io and nav_fcs partitions and a DDS agent; the smart actuators vote over the "
        "three flight-control replicas) on sim/pilots/default.yaml (hold, a 90° turn, a 1000 ft "
        "climb) in light turbulence and a 10 kt wind, and print the summary judged from the "
        "world's truth trace. Same options as `ima launch`, e.g. --kill-node node2@120.",
    )
    launch.add_run_arguments(parser, kind="demo")
    return parser


def run(args: argparse.Namespace) -> int:
    opts = launch.options_from(args, system=system_path("rpas_triplex"), kind="demo")
    return launch.launch_and_summarise(opts, args.json,
                                       not args.no_recording)
