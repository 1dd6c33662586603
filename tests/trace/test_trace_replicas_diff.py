# SPDX-License-Identifier: Apache-2.0
"""ima trace replicas (the channels against the voted value, vote-outs) and ima trace diff."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from ima.canbus import codec
from ima.trace import diff, replicas, source
from ima.trace.decode import Decoder

ROOT = Path(__file__).resolve().parents[2]


def _cmd(ch: str, elev: float, t_ns: int) -> dict:
    m = codec.MESSAGES[f"ACT_CMD_{ch}"]
    data = m.encode_dict({f"ELEV_CMD_{ch}": elev, f"AIL_CMD_{ch}": 0.0, f"RUD_CMD_{ch}": 0.0,
                          f"THR_CMD_{ch}": 0.5, f"CMD_CNT_{ch}": 0})
    return {"t_ns": t_ns, "kind": "can_tx", "id": m.frame_id, "ext": True, "len": 8,
            "data": data.hex(), "from": f"node{'ABC'.index(ch) + 1}/io"}


def _write(path: Path, recs: list[dict]) -> None:
    path.mkdir(parents=True, exist_ok=True)
    (path / "can.jsonl").write_text("".join(json.dumps(r) + "\n" for r in recs))


def _replicas_run(tmp_path: Path, bad_from: int | None, silent_from: int | None) -> Path:
    recs = []
    for k in range(40):
        t = k * 50_000_000 + 1_000_000
        for ch in "ABC":
            if ch == "C" and silent_from is not None and k >= silent_from:
                continue
            elev = 0.1 + (0.5 if ch == "B" and bad_from is not None and k >= bad_from else 0)
            recs.append(_cmd(ch, elev, t + "ABC".index(ch) * 200_000))
    d = tmp_path / f"r{bad_from}-{silent_from}"
    _write(d, recs)
    return d


def test_a_miscomparing_channel_is_voted_out_after_persist_periods(tmp_path):
    d = _replicas_run(tmp_path, bad_from=10, silent_from=None)
    r = replicas.compute(source.load(d).frames, Decoder(), persist=3)
    assert r["voted_out"] == [{"node": "channel B", "channel": "B", "t_s": 0.6,
                               "reason": "miscompare", "source": "inferred"}]
    b = next(c for c in r["channels"] if c["channel"] == "B")
    assert abs(b["max_disagreement"]["ELEV_CMD"] - 0.5) < 1e-3
    a = next(c for c in r["channels"] if c["channel"] == "A")
    # B out, A and C agree: the voted value is theirs again
    assert a["max_disagreement"]["ELEV_CMD"] < 1e-3


def test_a_silent_channel_is_absent_and_the_worlds_decision_wins(tmp_path):
    d = _replicas_run(tmp_path, bad_from=None, silent_from=20)
    r = replicas.compute(source.load(d).frames, Decoder())
    assert [(v["channel"], v["reason"], v["t_s"]) for v in r["voted_out"]] == [
        ("C", "absent", 1.05)]
    (d / "world.jsonl").write_text(json.dumps({"t_ns": 1_095_000_000, "node": "node3",
                                               "kind": "voted_out", "channel": "C",
                                               "reason": "absent"}) + "\n")
    p = subprocess.run([sys.executable, "-m", "ima", "trace", "replicas", str(d), "--json"],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["voted_out"] == [{"node": "node3", "channel": "C", "t_s": 1.095,
                                 "reason": "absent", "source": "world"}]
    assert out["voted_out_inferred"][0]["t_s"] == 1.05


def test_two_left_that_disagree_vote_nobody_out(tmp_path):
    d = _replicas_run(tmp_path, bad_from=25, silent_from=5)
    r = replicas.compute(source.load(d).frames, Decoder())
    assert [v["channel"] for v in r["voted_out"]] == ["C"]  # absent; B vs A: undecidable


def test_diff_names_the_first_divergent_frame_and_signal(tmp_path):
    a = _replicas_run(tmp_path, bad_from=None, silent_from=None)
    b = _replicas_run(tmp_path, bad_from=12, silent_from=None)
    d = diff.first_divergence(source.load(a).frames, source.load(b).frames, Decoder())
    assert d["name"] == "ACT_CMD_B" and d["t_s"] == 0.6012
    assert [s["signal"] for s in d["signals"]] == ["ELEV_CMD_B"]
    assert diff.first_divergence(source.load(a).frames, source.load(a).frames) is None
    # a frame one run lacks
    c = _replicas_run(tmp_path, bad_from=None, silent_from=30)
    d = diff.first_divergence(source.load(a).frames, source.load(c).frames, Decoder())
    # A's ACT_CMD_C of period 30 (1.5014 s) is where C's next frame is ACT_CMD_A of period 31
    assert d["name"] == "ACT_CMD_C" and d["t_s"] == 1.5014, d
    assert d["b"]["id"] == codec.MESSAGES["ACT_CMD_A"].frame_id and d["signals"] == []
    p = subprocess.run([sys.executable, "-m", "ima", "trace", "diff", str(a), str(b), "--json"],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    fd = json.loads(p.stdout)["first_divergence"]
    assert fd["t_s"] == 0.6012 and fd["id"] == codec.MESSAGES["ACT_CMD_B"].frame_id


def test_plot_draws_signals_and_marks_the_runs_events(tmp_path):
    d = _replicas_run(tmp_path, bad_from=10, silent_from=None)
    (d / "world.jsonl").write_text(json.dumps({"t_ns": 600_000_000, "node": "node2",
                                               "kind": "voted_out", "channel": "B"}) + "\n")
    (d / "node2.jsonl").write_text(json.dumps({"t_ns": 650_000_000, "node": "node2", "kind": "hm",
                                               "partition": "io", "error": "APPLICATION_ERROR",
                                               "action": "IGNORE"}) + "\n")
    (d / "launch.json").write_text(json.dumps({"faults": [{"id": "f1", "class": "wrong_output",
                                                           "t_s": 0.5}]}))
    png = tmp_path / "p.png"
    p = subprocess.run([sys.executable, "-m", "ima", "trace", "plot", str(d), "--signal",
                        "ACT_CMD_B.ELEV_CMD_B", "--signal", "ACT_CMD_A.THR_CMD_A", "-o", str(png)],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    assert "ACT_CMD_B.ELEV_CMD_B (40 samples)" in p.stdout and "3 events marked" in p.stdout
    assert png.stat().st_size > 5000
    bad = subprocess.run([sys.executable, "-m", "ima", "trace", "plot", str(d), "--signal",
                          "ACT_CMD_B.NOPE", "-o", str(png)], capture_output=True, text=True,
                         cwd=ROOT)
    assert bad.returncode != 0 and "has no signal NOPE" in bad.stderr
    assert "Traceback" not in bad.stderr
