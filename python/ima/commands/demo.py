# SPDX-License-Identifier: Apache-2.0
"""`ima demo`: launches the triplex system (config/systems/rpas_triplex.yaml: three emulated
processors, voted flight control) on the demonstration mission (config/missions/demo.yaml,
sim/pilots/demo_mission.yaml: tracks, an arc, a hold, a survey scan, a C2 link lost and
regained, the automatic landing to a stop) and prints the summary, leg by leg."""

from __future__ import annotations

import argparse

from ima import paths
from ima.commands import launch
from ima.launch.options import system_path

DEMO_DURATION_S = 1750.0  # the landing and the stop are in by about 1700 s


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo",
        help="launch the triplex on the demonstration mission, down to the runway",
        description="Launch config/systems/rpas_triplex.yaml (three ARINC 653 processors, each "
        "with the io, nav_fcs, flight data recorder and mission manager partitions and a DDS "
        "agent; the smart actuators vote over the three flight-control replicas) on the "
        "mission config/missions/demo.yaml, uplinked over the C2 link: two tracks, an arc, a "
        "hold, a four-pass survey scan, the C2 link lost for 50 s on the way to the final "
        "approach (the plan's lost-link procedure, then the mission resumes), and the automatic "
        "landing to a stop; light turbulence and a 10 kt wind. Prints the summary judged from "
        "the world's truth trace, leg by leg, and writes track.png. Same options as `ima "
        "launch`, e.g. --kill-node node2@120.",
    )
    launch.add_run_arguments(parser, kind="demo")
    parser.set_defaults(duration=DEMO_DURATION_S)
    return parser


def run(args: argparse.Namespace) -> int:
    root = paths.repo_root()
    if args.mission is None:
        args.mission = root / "config" / "missions" / "demo.yaml"
        if args.pilot is None:
            args.pilot = root / "sim" / "pilots" / "demo_mission.yaml"
    opts = launch.options_from(args, system=system_path("rpas_triplex"), kind="demo")
    return launch.launch_and_summarise(opts, args.json,
                                       not args.no_recording)
