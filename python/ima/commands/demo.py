# SPDX-License-Identifier: Apache-2.0
"""`ima demo`: flies the default 10-minute mission of one emulated processor (world, CAN bus,
io + nav_fcs partitions) and prints the flight summary."""

from __future__ import annotations

import argparse

from ima.commands import fly


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo",
        help="fly the default 10-minute autopilot mission and print the flight summary",
        description="Fly sim/pilots/default.yaml (hold, a 90° turn, a 1000 ft climb) with one "
        "ARINC 653 processor over the virtual CAN bus in light turbulence and a 10 kt wind, "
        "and print the summary judged from the world's truth trace. Same options as `ima fly`.",
    )
    fly.add_flight_arguments(parser)
    return parser


def run(args: argparse.Namespace) -> int:
    return fly.run(args)
