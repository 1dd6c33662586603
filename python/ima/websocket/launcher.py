# SPDX-License-Identifier: Apache-2.0
"""The launcher's side of `--live`: start() runs `python -m ima.websocket` and waits until it
listens; finish() tells it the run has ended and waits for it to serve the rest."""

from __future__ import annotations

import json
import select
import subprocess
import sys
import time
from pathlib import Path

from ima.errors import ImaError

_LISTEN_TIMEOUT_S = 20.0
_FINISH_TIMEOUT_S = 30.0


def start(run_dir: Path, nodes: list[str], port: int) -> tuple[subprocess.Popen, str]:
    """The live server's process and its URL, once it listens."""
    cmd = [sys.executable, "-m", "ima.websocket", str(run_dir), "--port", str(port), "--nodes",
           ",".join(nodes)]
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    deadline = time.monotonic() + _LISTEN_TIMEOUT_S
    while time.monotonic() < deadline:
        ready, _, _ = select.select([proc.stdout], [], [], 0.1)
        if ready:
            line = proc.stdout.readline()
            try:
                return proc, json.loads(line)["url"]
            except (ValueError, KeyError, TypeError):
                break  # it failed: its error is on stderr
        if proc.poll() is not None:
            break
    proc.kill()
    _, err = proc.communicate()
    why = " ".join(err.decode(errors="replace").split())[-300:] or "it did not start"
    raise ImaError(f"--live: the live server failed: {why}")


def finish(proc: subprocess.Popen) -> dict:
    """{"live_messages": N} once it has served the traces' last lines."""
    try:
        out, _ = proc.communicate(input=b"", timeout=_FINISH_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        return {"live_messages": None}
    try:
        counts = json.loads(out.decode().strip().splitlines()[-1])["topics"]
    except (ValueError, IndexError, KeyError):
        return {"live_messages": None}
    return {"live_messages": sum(counts.values())}
