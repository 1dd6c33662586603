# SPDX-License-Identifier: Apache-2.0
"""`ima trace SUBCOMMAND`: CAN trace analysis of a run directory or of a log python-can reads.
Each subcommand is a module of ima.trace."""

from __future__ import annotations

import argparse

SUBCOMMANDS = {
    "stats": ("bus load per window (exact stuffed frame lengths) and, per identifier, periods "
              "against the DBC's cycle times, gaps, deadline misses; error frames, bus-off",
              "ima.trace.stats"),
    "replicas": ("the redundancy channels' commands against each other and the voted value, "
                 "and when a channel was voted out", "ima.trace.replicas"),
    "diff": ("the first frame at which two runs' CAN traffic diverge, and its signals",
             "ima.trace.diff"),
    "export": ("the frames as an ASC, BLF, candump, TRC or CSV log (python-can's writers)",
               "ima.trace.export"),
    "plot": ("signals over time; a run's faults, vote-outs and HM decisions marked",
             "ima.trace.plot"),
    "recover": ("RUN_DIR/run.mcap from whatever a run left (a killed run)", "ima.trace.recover"),
}


def add_parser(subparsers) -> argparse.ArgumentParser:
    import importlib

    parser = subparsers.add_parser(
        "trace", help="analyse the CAN traffic of a run or of a python-can log",
        description="Analyse the CAN frames of a run directory (its can.jsonl) or of a log "
        "python-can reads (ASC, BLF, candump .log, TRC, CSV), decoded with config/can/rpas.dbc "
        "or --dbc (docs/can-trace.md).")
    sub = parser.add_subparsers(dest="trace_command", metavar="SUBCOMMAND", required=True)
    for name, (help_text, module) in SUBCOMMANDS.items():
        mod = importlib.import_module(module)
        p = sub.add_parser(name, help=help_text, description=help_text[0].upper() + help_text[1:]
                           + ".")
        mod.add_arguments(p)
        p.set_defaults(trace_run=mod.run)
    return parser


def run(args: argparse.Namespace) -> int:
    return args.trace_run(args)
