# SPDX-License-Identifier: Apache-2.0
"""The arbitrary-value replica: a wrong_output fault of each mode on one node of the triplex
(--fault NODE:wrong_output@...: io's --fault argument, added to that node's module). Every mode is voted out by
the actuators, the replica's own monitor sees it, and io reports the fault in its node's trace."""

from __future__ import annotations

import json

import pytest

MAF_S = 0.05
AT_S = 10.0
FAULTY = "node2"

MODES = {
    "bias": "mode=bias,axis=elev,value=0.3",
    "random": "mode=random,axis=elev,seed=5",
    "oscillating": "mode=oscillating,axis=rud,value=0.5,period_osc=2s",
    "hardover": "mode=hardover,axis=ail,value=-1",
}
TRANSIENT = {"random": 10.0}  # active 10 s, then cleared


def fault(mode: str):
    from faultinject import grammar

    dur = f"~{TRANSIENT[mode]:g}" if mode in TRANSIENT else ""
    return grammar.parse(f"{FAULTY}:wrong_output@{AT_S:g}{dur}:{MODES[mode]}", f"wo-{mode}")


@pytest.mark.parametrize("mode", list(MODES))
def test_wrong_output_of_each_mode_is_voted_out(launches, mode):
    run = launches.launch(f"wrong_output_{mode}", duration_s=30.0, seed=3,
                          faults=[fault(mode)])
    s = run.summary
    brief = json.dumps({k: s.get(k) for k in ("crashed", "flown_s", "voted_out", "membership",
                                              "monitor_reports")})[:3000]
    assert not s["crashed"] and s["flown_s"] >= 29, brief
    # the actuators vote node2 out for what it commands, within persist (3) frames and one
    assert [(v["node"], v["reason"]) for v in s["voted_out"]] == [(FAULTY, "miscompare")], brief
    assert AT_S <= s["voted_out"][0]["t_s"] <= AT_S + 4 * MAF_S, brief
    # node2 is alive (membership unchanged); its own monitor knows its output is out
    assert s["membership"] == ["node1", "node2", "node3"], brief
    assert any(r["node"] == FAULTY and "own output voted out" in r["text"]
               for r in s["monitor_reports"]), brief
    # io reports the fault once per spell, with the fixed prefix the oracles parse
    texts = [(r["t_ns"], r["text"]) for r in run.records(f"{FAULTY}.jsonl", "app_message")
             if r["text"].startswith(f"fault wo-{mode} wrong_output ")]
    applied = [(t, x) for t, x in texts if " applied " in x]
    assert len(applied) == 1, texts
    t_applied, text = applied[0]
    assert AT_S * 1e9 <= t_applied < (AT_S + MAF_S) * 1e9, texts
    assert text.startswith(f"fault wo-{mode} wrong_output applied mode={mode} axis="), text
    cleared = [(t, x) for t, x in texts if " cleared " in x]
    if mode in TRANSIENT:
        # a transient fault: cleared at io's first transmission after its end
        assert len(cleared) == 1 and 20e9 <= cleared[0][0] < 20e9 + MAF_S * 1e9, texts
        assert "frames=200" in cleared[0][1], texts  # one command a frame for 10 s
    else:
        assert cleared == [], texts
    # nobody else has a fault to report
    for node in ("node1", "node3"):
        assert not [r for r in run.records(f"{node}.jsonl", "app_message")
                    if r["text"].startswith("fault ")]
