# SPDX-License-Identifier: Apache-2.0
"""The launcher's side of the recording: start() runs `python -m ima.recording --follow
--wait-summary` as the run starts (it follows the traces while the run flies, on the CPU the
lockstep leaves idle); flown() tells it the run's processes have ended; finish() tells it the
summary is final, waits for it, and returns the summary's recording fields."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from ima.recording.write import NAME


def start(run_dir: Path, nodes: list[str]) -> subprocess.Popen | None:
    try:
        return subprocess.Popen([sys.executable, "-m", "ima.recording", str(run_dir),
                                 "--follow", "--nodes", ",".join(nodes), "--wait-summary"],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE)
    except OSError:
        return None


def flown(proc: subprocess.Popen | None) -> None:
    """The run's processes have ended: every trace is complete."""
    if proc is None:
        return
    try:
        proc.stdin.write(b"ended\n")
        proc.stdin.flush()
    except OSError:
        pass  # it has failed: finish() says why


def abandon(proc: subprocess.Popen | None, run_dir: Path) -> None:
    """The run did not start or failed to: no recording (its partial file is removed)."""
    if proc is None:
        return
    proc.kill()
    proc.communicate()
    (Path(run_dir) / (NAME + ".part")).unlink(missing_ok=True)


def finish(proc: subprocess.Popen | None, timeout_s: float = 600.0) -> dict:
    """{"recording": path} or {"recording": None, "recording_error": why}."""
    if proc is None:
        return {"recording": None, "recording_error": "the recorder could not be started"}
    try:
        out, err = proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        return {"recording": None, "recording_error": f"no recording within {timeout_s:g} s"}
    if proc.returncode != 0:
        why = " ".join(err.decode(errors="replace").split())[-300:] or f"exit {proc.returncode}"
        return {"recording": None, "recording_error": why}
    try:
        counts = json.loads(out.decode().strip().splitlines()[-1])
    except (ValueError, IndexError):
        counts = {}
    return {"recording": counts.get("file") or NAME,
            "recording_messages": sum((counts.get("topics") or {}).values())}
