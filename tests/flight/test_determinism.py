# SPDX-License-Identifier: Apache-2.0
"""Same seed, same inputs: the lockstep makes two flights byte-identical, world truth, CAN bus
trace and node trace alike; another seed flies differently."""

from __future__ import annotations

import pytest

FILES = ("truth.jsonl", "can.jsonl", "node1.jsonl", "world.jsonl")


@pytest.fixture(scope="module")
def runs(flights):
    kw = dict(duration_s=60.0, turbulence="light", wind_kt=10)
    return (flights.fly("det_a", seed=11, **kw), flights.fly("det_b", seed=11, **kw),
            flights.fly("det_c", seed=12, **kw))


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


def test_other_seed_differs(runs):
    a, _, c = runs
    assert (a.run_dir / "truth.jsonl").read_bytes() != (c.run_dir / "truth.jsonl").read_bytes()
