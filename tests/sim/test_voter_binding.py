# SPDX-License-Identifier: Apache-2.0
"""The Python binding of the C voter (imaworld.voter): struct layouts match the library, and
the binding gives the rules of nodes/include/voter/voter.h on a sample of the truth table."""

from __future__ import annotations

import ctypes
import math
import os
import subprocess
import sys

import pytest

from ima.errors import ImaError
from imaworld import voter as V

HEALTHY = (0.5, -0.25, 0.0, 0.75)
THR = (0.1, 0.1, 0.1, 0.1)
SAFE = (-0.5, -1.5, -2.5, -3.5)


def test_struct_sizes_match_the_library():
    lib = V.library()
    assert ctypes.sizeof(V.VoterCfg) == lib.voter_sizeof_cfg()
    assert ctypes.sizeof(V.VoterState) == lib.voter_sizeof_voter()
    assert ctypes.sizeof(V.VoterOut) == lib.voter_sizeof_out()


def test_names_and_mid3():
    assert [V.status_name(s) for s in range(5)] == list(V.STATUS_NAMES)
    assert [V.reason_name(r) for r in range(3)] == list(V.REASON_NAMES)
    assert V.mid3(3.0, 1.0, 2.0) == 2.0
    assert V.mid3(-1.0, -3.0, -2.0) == -2.0
    assert V.mid3(math.inf, -math.inf, 0.25) == 0.25
    assert V.mid3(math.nan, 2.0, 1.0) == 1.0
    assert V.mid3(math.nan, math.nan, -4.0) == -4.0
    assert math.isnan(V.mid3(math.nan, math.nan, math.nan))
    assert V.mask_letters(0b101) == "AC"


@pytest.mark.parametrize("cfg", [
    dict(n=0), dict(n=4), dict(persist=0), dict(thresholds=(0.1, -0.1, 0.1, 0.1)),
    dict(thresholds=(0.1, math.nan, 0.1, 0.1)), dict(thresholds=(0.1,) * 3),
])
def test_bad_configurations_are_refused(cfg):
    args = dict(n=3, dim=4, thresholds=THR, persist=3, safe=SAFE) | cfg
    with pytest.raises(ImaError, match="bad voter configuration"):
        V.Voter(**args)


def oracle(n, persist, present, failed, xs):
    """One frame of the rules from a voter whose `failed` channels are out, counts 0."""
    cand = [c for c in range(n) if present >> c & 1 and not failed >> c & 1]
    k = len(cand)
    if k == 3:
        value = tuple(sorted(xs[c][d] for c in cand)[1] for d in range(4))
    elif k == 2:
        value = tuple((xs[cand[0]][d] + xs[cand[1]][d]) / 2 for d in range(4))
    elif k == 1:
        value = tuple(xs[cand[0]])
    else:
        value = SAFE
    status = ("SAFE", "SINGLE", "AVG2", "MID3")[k]
    used = sum(1 << c for c in cand)

    def off(c):
        return any(abs(xs[c][d] - value[d]) > THR[d] for d in range(4))

    pair_bad = k == 2 and any(off(c) for c in cand)
    bad, mis = 0, 0
    reasons = {}
    for c in range(n):
        if failed >> c & 1:
            continue
        if not present >> c & 1:
            bad |= 1 << c
            reasons[c] = "absent"
        elif k == 3 and off(c):
            bad |= 1 << c
            reasons[c] = "miscompare"
        elif pair_bad:
            mis |= 1 << c
    newly_failed = bad if persist == 1 else 0
    disagree = pair_bad and persist == 1
    if disagree:
        status, used, value = "DISAGREE", 0, SAFE
    return V.Vote(value, status, used, bad | mis, newly_failed, disagree), \
        {c: r for c, r in reasons.items() if newly_failed >> c & 1}


@pytest.mark.parametrize("n", [1, 2, 3])
@pytest.mark.parametrize("persist", [1, 3])
def test_truth_table_sample(n, persist):
    all_ch = (1 << n) - 1
    for failed in range(1 << n):
        for present in range(8):
            for mis in range(8):
                v = V.Voter(n, 4, THR, persist, SAFE)
                for _ in range(persist):  # fail `failed` by absence
                    v.step([None if failed >> c & 1 else HEALTHY for c in range(3)])
                assert v.failed == failed
                xs = [list(HEALTHY) for _ in range(3)]
                for c in range(3):
                    if mis >> c & 1:
                        xs[c][0] += 0.5 * (c + 1)
                got = v.step([xs[c] if present >> c & 1 else None for c in range(3)])
                want, reasons = oracle(n, persist, present & all_ch, failed, xs)
                assert got == want, (n, persist, failed, present, mis)
                for c, r in reasons.items():
                    assert v.reason(c) == r
                assert v.disagree == want.newly_disagree


def test_persistence_reset_and_determinism():
    def run():
        v = V.Voter(3, 4, THR, 3, SAFE)
        biased = (0.5 + 0.3,) + HEALTHY[1:]
        seq = [[HEALTHY, biased, HEALTHY]] * 2 + [[HEALTHY] * 3] + \
              [[HEALTHY, biased, HEALTHY]] * 3 + [[HEALTHY, None, None]] * 3
        out = [v.step(x) for x in seq]
        return v, out

    v, out = run()
    assert [o.newly_failed for o in out] == [0, 0, 0, 0, 0, 0b010, 0, 0, 0b100]
    assert [o.status for o in out] == ["MID3"] * 6 + ["SINGLE"] * 3
    assert v.reason(1) == "miscompare" and v.reason(2) == "absent" and v.frames == 9
    assert out[5].value == HEALTHY
    assert run()[1] == out
    v.reset()
    assert v.failed == 0 and v.frames == 0 and v.counts == (0, 0, 0)
    assert v.step([HEALTHY] * 3).status == "MID3"


def test_a_missing_library_says_how_to_build_it(tmp_path):
    code = "from imaworld import voter; voter.Voter(3, 4, (0.1,) * 4, 3)"
    env = dict(os.environ, IMA_VOTER_LIB=str(tmp_path / "nope.so"))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       timeout=60)
    assert p.returncode != 0
    assert "nope.so is missing (run ./ima to build" in p.stderr


def test_the_default_place_is_the_build_tree(monkeypatch, tmp_path):
    monkeypatch.delenv("IMA_VOTER_LIB", raising=False)
    monkeypatch.setenv("IMA_BUILD_DIR", str(tmp_path))
    assert V.library_path() == tmp_path / "nodes" / "libima_voter.so"
