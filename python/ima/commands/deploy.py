# SPDX-License-Identifier: Apache-2.0
"""`ima deploy`: turns a system model into one module per node and the partitions' C glue,
and prints the deployment summary."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ima import outdir
from ima.deploy import generate, load_system
from ima.deploy.report import print_summary


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "deploy",
        help="generate the node modules and C glue of a system model",
        description="Read a system model (config/systems/*.yaml), check it, and write one "
        "ARINC 653 module per node (validated against the module schema) and the partitions' "
        "C glue headers into DIR; print the deployment summary. Exit code 2: the model or a "
        "generated module is invalid.",
    )
    parser.add_argument("system", metavar="SYSTEM.yaml", type=Path, help="the system model")
    parser.add_argument("-o", "--out", metavar="DIR", type=outdir.dir_arg, required=True,
                        help="where to write the modules (DIR/<node>.xml) and DIR/glue/")
    parser.add_argument("--json", action="store_true",
                        help="print the summary as one JSON object instead of the table")
    return parser


def run(args: argparse.Namespace) -> int:
    system = load_system(args.system)
    result = generate(system, outdir.usable_dir(args.out, "--out"))
    if args.json:
        json.dump(result.summary, sys.stdout)
        sys.stdout.write("\n")
    else:
        print_summary(result.summary, sys.stdout)
    return 0
