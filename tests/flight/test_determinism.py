# SPDX-License-Identifier: Apache-2.0
"""Same seed, same inputs: the lockstep makes two flights byte-identical, world truth, CAN bus
trace and node trace alike; another seed flies differently. The quanta the world skips (it asks
for those its tasks fall in) change nothing: a world granted every quantum flies the same; nor
do the windows an SKE runs ahead of the bus (its partitions that are not system partitions);
nor does the world's C++ (imaworld.core): its Python flies the same, a landing too."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from flight_helpers import fault

FILES = ("truth.jsonl", "can.jsonl", "node1.jsonl", "world.jsonl")


@pytest.fixture(scope="module")
def runs(flights):
    kw = dict(duration_s=60.0, turbulence="light", wind_kt=10)
    return (flights.fly("det_a", seed=11, **kw), flights.fly("det_b", seed=11, **kw),
            flights.fly("det_c", seed=12, **kw))


@pytest.fixture(scope="module")
def every_quantum(flights):
    return flights.fly("det_every_quantum", seed=11, duration_s=60.0, turbulence="light",
                       wind_kt=10, test_switches=["world:every-quantum"])


@pytest.fixture(scope="module")
def ske_every_quantum(flights):
    return flights.fly("det_ske_every_quantum", seed=11, duration_s=60.0, turbulence="light",
                       wind_kt=10, test_switches=["ske:every-quantum"])


@pytest.fixture(scope="module")
def python_only(flights):
    return flights.fly("det_python_only", seed=11, duration_s=60.0, turbulence="light",
                       wind_kt=10, test_switches=["world:python-only"])


def _ticks(run, client: str) -> dict:
    (c,) = [c for c in json.loads((run.run_dir / "canbus.json").read_text())["clients"]
            if c["name"] == client]
    return c


def _without_switches(data: bytes) -> bytes:
    """A node's trace without its test_switch events (the SKE records its switches)."""
    return b"".join(line for line in data.splitlines(keepends=True)
                    if b'"kind":"test_switch"' not in line)


@pytest.mark.parametrize("name", FILES)
def test_same_seed_identical_traces(runs, name):
    a, b, _ = runs
    da = (a.run_dir / name).read_bytes()
    db = (b.run_dir / name).read_bytes()
    assert len(da) > 100, f"{name} is nearly empty"
    if da != db:
        la, lb = da.splitlines(), db.splitlines()
        first = next(i for i, (x, y) in enumerate(zip(la, lb)) if x != y) if la[:len(lb)] != lb[:len(la)] else min(len(la), len(lb))
        pytest.fail(f"{name} differs first at line {first + 1}:\n{la[first:first+1]}\n{lb[first:first+1]}")


@pytest.mark.parametrize("name", FILES)
def test_skipped_quanta_change_nothing(runs, every_quantum, name):
    a = runs[0]
    assert (a.run_dir / name).read_bytes() == (every_quantum.run_dir / name).read_bytes(), name
    skipping, every = _ticks(a, "world"), _ticks(every_quantum, "world")
    assert every["ticks_skipped"] == 0 and skipping["ticks_skipped"] > 0.3 * every["ticks"]
    assert skipping["ticks"] + skipping["ticks_skipped"] == every["ticks"]


@pytest.mark.parametrize("name", FILES)
def test_windows_run_ahead_change_nothing(runs, ske_every_quantum, name):
    a, b = runs[0], ske_every_quantum
    assert _without_switches((a.run_dir / name).read_bytes()) == \
        _without_switches((b.run_dir / name).read_bytes()), name
    ahead, every = _ticks(a, "node1"), _ticks(b, "node1")
    # woken for its io windows only (2 quanta of 5), not for every window (3 of 5)
    assert ahead["ticks"] + ahead["ticks_skipped"] == every["ticks"] + every["ticks_skipped"]
    assert ahead["ticks"] < every["ticks"], (ahead, every)


@pytest.mark.parametrize("name", FILES)
def test_the_worlds_cplusplus_changes_nothing(runs, python_only, name):
    assert (runs[0].run_dir / name).read_bytes() == (python_only.run_dir / name).read_bytes()


def test_a_landing_with_the_worlds_cplusplus_or_its_python(flights):
    """The ground: the wheels, the brakes and the roll-out, judged in Python either way."""
    data = Path(__file__).resolve().parents[1] / "mission" / "data"
    kw = dict(mission=data / "approach.yaml", pilot=data / "approach_pilot.yaml",
              duration_s=430.0, seed=1, turbulence="none")
    a = flights.fly("det_land", **kw)
    b = flights.fly("det_land_python_only", test_switches=["world:python-only"], **kw)
    landing = json.loads((a.run_dir / "world.json").read_text())["landing"]
    assert landing["stopped"], landing
    for name in FILES:
        assert (a.run_dir / name).read_bytes() == (b.run_dir / name).read_bytes(), name


def test_a_crash_stops_the_run_in_its_quantum_either_way(flights):
    """Near the limits a crash is judged by, the world asks for every quantum: the run stops in
    the quantum of the crash whether it skips quanta elsewhere or not."""
    kw = dict(duration_s=30.0, seed=11, judge=False,
              faults=[fault("world:actuator_hardover@5:surface=elev,value=1", "hard")])
    a = flights.fly("det_crash", **kw)
    b = flights.fly("det_crash_every_quantum", test_switches=["world:every-quantum"], **kw)
    assert a.summary["crashed"], a.summary
    for name in FILES:
        assert (a.run_dir / name).read_bytes() == (b.run_dir / name).read_bytes(), name
    assert _ticks(a, "world")["ticks_skipped"] > 0


def test_other_seed_differs(runs):
    a, _, c = runs
    assert (a.run_dir / "truth.jsonl").read_bytes() != (c.run_dir / "truth.jsonl").read_bytes()
