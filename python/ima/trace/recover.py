# SPDX-License-Identifier: Apache-2.0
"""`ima trace recover RUN_DIR`: RUN_DIR/run.mcap from whatever a run left — a run killed
(kill -9), a run whose recorder failed. Lines the kill cut are skipped and counted."""

from __future__ import annotations

import json
from pathlib import Path


def add_arguments(p) -> None:
    p.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="a run directory")
    p.add_argument("--json", action="store_true", help="the counts as one JSON object")


def run(args) -> int:
    from ima.recording import write

    r = write.record(args.run_dir)
    if args.json:
        print(json.dumps(r))
    else:
        cut = sum(r["skipped_lines"].values())
        print(f"{r['file']}: {sum(r['topics'].values())} messages on {len(r['topics'])} "
              f"channels, {r['bytes']:,} bytes"
              + (f"; {cut} cut lines left out ({', '.join(r['skipped_lines'])})" if cut else ""))
    return 0
