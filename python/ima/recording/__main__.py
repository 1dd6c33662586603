# SPDX-License-Identifier: Apache-2.0
"""python -m ima.recording RUN_DIR [--wait-summary]: writes RUN_DIR/run.mcap.

With --wait-summary (the launcher's way: it starts the recorder as soon as the run's
processes have ended, so that the recording is made on the other CPU while the summary is
judged and plotted) the traces are converted at once, then the recorder waits for its
standard input to close and adds the summary's verdicts. Prints its counts as JSON."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ima.errors import ImaError
from ima.recording import write


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m ima.recording")
    p.add_argument("run_dir", type=Path)
    p.add_argument("--wait-summary", action="store_true")
    args = p.parse_args(argv)

    def wait() -> None:
        if args.wait_summary:
            sys.stdin.read()  # EOF: summary.json is final

    try:
        counts = write.record(args.run_dir, before_verdicts=wait)
    except ImaError as e:
        print(f"ima: recording: {e}", file=sys.stderr)
        return 1
    print(json.dumps(counts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
