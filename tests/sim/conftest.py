# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the world tests: the world in-process on a loopback bus, or as a process on the
stand-in lockstep bus (fakebus.py)."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fakebus import FakeBus, LoopbackBus  # noqa: E402

from conftest_helpers import ACT_CMDS, NS, PILOTS, act_cmd_injector, model_voting  # noqa: E402

@dataclass
class LocalRun:
    world: object
    bus: LoopbackBus
    run_dir: Path

    def truth(self) -> list[dict]:
        return [json.loads(x) for x in (self.run_dir / "truth.jsonl").read_text().splitlines()]

    def events(self) -> list[dict]:
        return [json.loads(x) for x in (self.run_dir / "world.jsonl").read_text().splitlines()]

    def summary(self) -> dict:
        return json.loads((self.run_dir / "world.json").read_text())


@pytest.fixture
def local_world(tmp_path):
    """local_world(script, seconds, cmd=None|'trim'|f(t, trim), seed=0, **opts) -> LocalRun.
    channel_cmd=f(channel, t, trim) sends ACT_CMD_A, _B and _C (None: that channel is silent)."""
    from imaworld import pilot
    from imaworld.world import Options, World

    n = [0]

    def run(script, seconds: float, cmd=None, seed: int = 0, extra_injector=None,
            channel_cmd=None, **opts):
        n[0] += 1
        run_dir = tmp_path / f"local{n[0]}"
        if not isinstance(script, pilot.PilotScript):
            script = pilot.load(PILOTS / script) if isinstance(script, str) else \
                pilot.parse(script)
        bus = LoopbackBus(round(seconds * NS))
        if opts.get("channels") is not None and "voting" not in opts:
            opts["voting"] = model_voting()
        w = World(bus, script, run_dir, Options(seed=seed, **opts))
        trim = (w.trim["elev"], w.trim["ail"], w.trim["rud"], w.trim["thr"])
        injectors = []
        if cmd == "trim":
            injectors.append(act_cmd_injector(lambda t: trim))
        elif cmd is not None:
            injectors.append(act_cmd_injector(lambda t: cmd(t, trim)))
        if channel_cmd is not None:
            injectors += [act_cmd_injector(lambda t, ch=ch: channel_cmd(ch, t, trim), msg)
                          for ch, msg in enumerate(ACT_CMDS)]
        if extra_injector is not None:
            injectors.append(extra_injector)
        bus.injector = lambda a, b: [f for i in injectors for f in i(a, b)]
        w.run()
        return LocalRun(w, bus, run_dir)

    return run


@pytest.fixture
def world_process(tmp_path):
    """world_process(pilot, seconds, args=[...], injector=None) -> (CompletedProcess, run_dir,
    FakeBus): `python -m imaworld` as a LOCKSTEP client of the stand-in bus."""
    n = [0]

    def run(pilot_file, seconds: float, args=(), injector=None, timeout: float = 120):
        n[0] += 1
        sock = str(tmp_path / f"bus{n[0]}.sock")
        run_dir = tmp_path / f"run{n[0]}"
        bus = FakeBus(sock, lockstep_clients=1, end_ns=round(seconds * NS),
                      injector=injector).start()
        p = subprocess.run([sys.executable, "-m", "imaworld", "--bus", sock, "--run-dir",
                            str(run_dir), "--pilot", str(pilot_file), *map(str, args)],
                           capture_output=True, text=True, timeout=timeout)
        bus.join(30)
        return p, run_dir, bus

    return run
