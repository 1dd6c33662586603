# SPDX-License-Identifier: Apache-2.0
"""Fixtures shared by the system tests: run the real ima-ske on a module, read its trace."""

from __future__ import annotations

import json
import os
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BUILD = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build"))
SKE = BUILD / "ske" / "ima-ske"
PARTITIONS = BUILD / "partitions"
EXAMPLES = ROOT / "config" / "examples"


@dataclass
class SkeRun:
    """What one ima-ske run left behind: exit code, output, trace events and statistics."""

    returncode: int
    stdout: str
    stderr: str
    events: list[dict] = field(default_factory=list)
    stats: dict | None = None
    trace_path: Path | None = None

    def of_kind(self, kind: str, **match) -> list[dict]:
        return [e for e in self.events if e["kind"] == kind
                and all(e.get(k) == v for k, v in match.items())]

    def app_messages(self, partition: str | None = None) -> list[str]:
        return [e["text"] for e in self.events if e["kind"] == "app_message"
                and (partition is None or e["src"] == partition)]


def _env() -> dict:
    env = dict(os.environ)
    env["IMA_PARTITION_PATH"] = f"{PARTITIONS}:{env.get('IMA_PARTITION_PATH', '')}"
    return env


@pytest.fixture(scope="session")
def ske_binary() -> Path:
    if not SKE.is_file():
        pytest.fail(f"{SKE} is not built: run ./ima test (it builds first)")
    return SKE


@pytest.fixture
def run_ske(ske_binary, tmp_path):
    """run_ske(module, frames=N, args=[...], timeout=s) -> SkeRun, with trace and stats read."""
    counter = iter(range(1_000_000))

    def run(module, frames: int | None = 100, args=(), timeout: float = 120.0,
            trace: bool = True) -> SkeRun:
        n = next(counter)
        trace_path = tmp_path / f"trace{n}.jsonl"
        stats_path = tmp_path / f"stats{n}.json"
        cmd = [str(ske_binary), "--stats", str(stats_path)]
        if trace:
            cmd += ["--trace", str(trace_path)]
        if frames is not None:
            cmd += ["--frames", str(frames)]
        cmd += [str(a) for a in args] + [str(module)]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=_env())
        run_ = SkeRun(p.returncode, p.stdout, p.stderr, trace_path=trace_path if trace else None)
        if trace and trace_path.exists():
            run_.events = [json.loads(line) for line in trace_path.read_text().splitlines()]
        if stats_path.exists():
            run_.stats = json.loads(stats_path.read_text())
        return run_

    return run
