# SPDX-License-Identifier: Apache-2.0
"""Paths and the launched run shared by the launch tests."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ima.flight.summary import read_jsonl
from ima.launch import options as launch_options

ROOT = Path(__file__).resolve().parents[2]
TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"
SIMPLEX = ROOT / "config" / "systems" / "rpas_simplex.yaml"


@dataclass
class Run:
    """A launched run: its directory, its summary, what the launcher returned."""

    run_dir: Path
    summary: dict
    result: launch_options.LaunchRun

    def truth_between(self, t0_s: float, t1_s: float) -> list[dict]:
        return [r for r in read_jsonl(self.run_dir / "truth.jsonl")
                if t0_s <= r["t_ns"] / 1e9 < t1_s]

    def records(self, name: str, kind: str | None = None) -> list[dict]:
        return [r for r in read_jsonl(self.run_dir / name)
                if kind is None or r.get("kind") == kind]
