# SPDX-License-Identifier: Apache-2.0
"""python -m ima.recording RUN_DIR [--wait-summary] [--follow --nodes A,B]: writes
RUN_DIR/run.mcap. Prints its counts as JSON.

The launcher's way (recorder.py): with --follow it starts with the run and follows its traces
as they grow, on the CPU the lockstep leaves idle, until a line `ended` on its standard input
says the run's processes have ended; it then reads what is left. With --wait-summary it then
waits for its standard input to close (the summary is final) and adds the summary's
verdicts. Ctrl-C is the launcher's to handle: a following recorder ignores it and records the
run up to its stop."""

from __future__ import annotations

import argparse
import json
import os
import select
import signal
import sys
import time
from pathlib import Path

from ima.errors import ImaError
from ima.recording import write


class _Stdin:
    """The launcher's word: `ended` (the traces are complete), then end of file (the summary
    is final). End of file alone says both (the launcher has gone)."""

    def __init__(self) -> None:
        self.fd = sys.stdin.fileno()
        self.ended = self.closed = False

    def _read(self, timeout: float | None) -> None:
        ready, _, _ = select.select([self.fd], [], [], timeout)
        if ready:
            data = os.read(self.fd, 4096)
            if not data:
                self.ended = self.closed = True
            elif b"ended" in data:
                self.ended = True

    def run_ended(self) -> bool:
        if not self.ended:
            self._read(0)
        return self.ended

    def wait_ended(self, timeout: float) -> None:
        """Up to `timeout`, less if the word comes: the recorder's last reads start at once."""
        if not self.ended:
            self._read(timeout)

    def wait_closed(self) -> None:
        while not self.closed:
            self._read(None)


def _yield_to_the_flight() -> None:
    """Run only on CPU time the run leaves idle (SCHED_IDLE; else the lowest priority)."""
    try:
        os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
    except (OSError, AttributeError):
        try:
            os.nice(19)
        except OSError:
            pass


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m ima.recording")
    p.add_argument("run_dir", type=Path)
    p.add_argument("--wait-summary", action="store_true")
    p.add_argument("--follow", action="store_true")
    p.add_argument("--nodes", help="the run's nodes, comma-separated (with --follow)")
    args = p.parse_args(argv)
    stdin = _Stdin() if args.follow or args.wait_summary else None  # the launcher's word
    if args.follow:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        _yield_to_the_flight()

    def wait() -> None:
        if args.wait_summary:
            stdin.wait_closed()

    try:
        counts = write.record(args.run_dir, before_verdicts=wait,
                              follow=stdin.run_ended if args.follow else None,
                              pause=stdin.wait_ended if args.follow else time.sleep,
                              nodes=args.nodes.split(",") if args.nodes else None)
    except ImaError as e:
        print(f"ima: recording: {e}", file=sys.stderr)
        return 1
    print(json.dumps(counts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
