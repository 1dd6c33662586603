# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the flight tests: real flights (JSBSim world, CAN bus, one ima-ske node: the
one-node system `ima fly` launches) run once per session and shared by the tests that judge
them from the world's truth trace."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import cantools
import pytest

from ima.flight import summary as flight_summary
from ima.launch import options as launch_options
from ima.launch import run as launch_run

# The tests import their helpers (flight_helpers.py) from this folder.
sys.path.insert(0, str(Path(__file__).resolve().parent))

from flight_helpers import fly_unless_host_stalled  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DBC = ROOT / "config" / "can" / "rpas.dbc"


@dataclass
class Flight:
    run_dir: Path
    summary: dict
    returncodes: dict

    def truth(self) -> list[dict]:
        return list(flight_summary.read_jsonl(self.run_dir / "truth.jsonl"))

    def truth_between(self, t0_s: float, t1_s: float) -> list[dict]:
        return [r for r in self.truth() if t0_s <= r["t_ns"] / 1e9 < t1_s]

    def can_frames(self, name: str) -> list[tuple[float, dict]]:
        """(end time s, decoded signals) of every frame of message `name` on the bus."""
        db = cantools.database.load_file(DBC)
        msg = db.get_message_by_name(name)
        out = []
        for rec in flight_summary.read_jsonl(self.run_dir / "can.jsonl"):
            if rec.get("kind") == "can_tx" and rec.get("id") == msg.frame_id:
                out.append((rec["t_ns"] / 1e9, msg.decode(bytes.fromhex(rec["data"]))))
        return out


class FlightCache:
    def __init__(self, base: Path) -> None:
        self.base = base
        self.flights: dict[str, Flight] = {}

    def fly(self, name: str, system: Path | None = None, **kw) -> Flight:
        """`ima fly`: the one-node system (or `system`) launched."""
        if name not in self.flights:
            run_dir = self.base / name
            opts = launch_options.LaunchOptions(
                system=system or launch_options.system_path("rpas_simplex"), run_dir=run_dir,
                kind="fly", **kw)
            result = fly_unless_host_stalled(lambda: launch_run.launch(opts), run_dir, name)
            pilot = Path(opts.pilot) if opts.pilot else launch_options.default_pilot()
            summary = flight_summary.summarise(run_dir, pilot, opts.duration_s, result.wall_s)
            self.flights[name] = Flight(run_dir, summary, result.returncodes)
        return self.flights[name]


@pytest.fixture(scope="session")
def flights(tmp_path_factory) -> FlightCache:
    return FlightCache(tmp_path_factory.mktemp("flights"))


