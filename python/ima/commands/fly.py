# SPDX-License-Identifier: Apache-2.0
"""`ima fly`: the one-node system (config/systems/rpas_simplex.yaml) launched as `ima launch`
launches any system: the same options, run directory and summary."""

from __future__ import annotations

import argparse

from ima.commands import launch
from ima.launch.options import system_path


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "fly",
        help="fly the aircraft with one emulated processor: ima launch of rpas_simplex.yaml",
        description="Fly the c172p stand-in airframe in JSBSim with one ARINC 653 processor "
        "(config/systems/rpas_simplex.yaml: the io and nav_fcs partitions) over the virtual CAN "
        "bus, in lockstep emulated time, and judge the flight from the world's truth trace. "
        "The same as `ima launch config/systems/rpas_simplex.yaml`, with the same options.",
    )
    launch.add_run_arguments(parser, kind="fly")
    return parser


def run(args: argparse.Namespace) -> int:
    opts = launch.options_from(args, system=system_path("rpas_simplex"), kind="fly")
    return launch.launch_and_summarise(opts, args.json,
                                       not args.no_recording)
