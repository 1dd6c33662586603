# SPDX-License-Identifier: Apache-2.0
"""The launcher's side of the recording: start() runs `python -m ima.recording --wait-summary`
as soon as the run's processes have ended; finish() tells it the summary is final, waits
for it, and returns the summary's recording fields."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from ima.recording.write import NAME


def start(run_dir: Path) -> subprocess.Popen | None:
    try:
        return subprocess.Popen([sys.executable, "-m", "ima.recording", str(run_dir),
                                 "--wait-summary"], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    except OSError:
        return None


def finish(proc: subprocess.Popen | None, timeout_s: float = 600.0) -> dict:
    """{"recording": path} or {"recording": None, "recording_error": why}."""
    if proc is None:
        return {"recording": None, "recording_error": "the recorder could not be started"}
    try:
        out, err = proc.communicate(input=b"", timeout=timeout_s)
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
