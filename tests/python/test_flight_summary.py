# SPDX-License-Identifier: Apache-2.0
"""The flight summary's judgement: hold segments from a pilot script, errors from truth."""

from __future__ import annotations

import json

import pytest

from ima.flight import summary


def _script(tmp_path, events, settle=30):
    p = tmp_path / "p.yaml"
    p.write_text(json.dumps({
        "start": {"altitude_ft": 3000, "airspeed_kt": 100, "heading_deg": 90},
        "events": events, "evaluate": {"settle_s": settle}}))
    return p


def test_hold_segments_skip_settling_direct_and_link_loss(tmp_path):
    p = _script(tmp_path, [
        {"t": 0, "mode": "AUTOPILOT", "heading_deg": 90, "altitude_ft": 3000, "airspeed_kt": 100},
        {"t": 100, "heading_deg": 180},
        {"t": 200, "c2_link": "down"},
        {"t": 250, "c2_link": "up"},
        {"t": 300, "mode": "DIRECT"},
    ])
    segs = summary.hold_segments(p, 400)
    assert [(s.t0_s, s.t1_s, s.heading_deg) for s in segs] == [
        (30, 100, 90), (130, 200, 180), (280, 300, 180)]


def test_tracking_errors_wrap_heading_and_use_only_segments():
    seg = summary.HoldSegment(10, 20, heading_deg=2.0, altitude_ft=3000, airspeed_kt=100)
    truth = [{"t_ns": int(t * 1e9), "alt_ft": 3000 + d, "airspeed_kt": 100 - d,
              "heading_deg": (2 - d) % 360, "roll_deg": d * 3, "pitch_deg": 0}
             for t, d in ((5, 50.0), (10, 4.0), (15, -3.0), (25, 80.0))]
    e = summary.tracking_errors(truth, [seg])
    assert e["samples_judged"] == 2
    assert e["alt_err_ft_max"] == 4.0 and e["airspeed_err_kt_max"] == 4.0
    assert e["heading_err_deg_max"] == 4.0  # 358° against 002° is 4°, not 356°
    assert e["alt_err_ft_rms"] == pytest.approx(((16 + 9) / 2) ** 0.5, abs=0.01)
    assert e["bank_deg_max"] == 240.0  # over the whole flight, segments or not


def test_wrap180():
    assert summary.wrap180(190) == -170 and summary.wrap180(-190) == 170


def test_a_window_kept_past_its_cpu_budget_without_a_fault_is_told_as_a_host_stall(tmp_path):
    """The summary lists the windows the SKE stopped at their CPU budget (one reading of each
    node's trace, with its HM events); the launch names those of partitions no fault acts on,
    and its report warns of them."""
    import io

    from rich.console import Console

    from ima.launch import report

    lines = [
        {"t_ns": 1, "node": "node1", "src": "ske", "kind": "window_start", "partition": "io"},
        {"t_ns": 312_400_000_000, "node": "node1", "src": "ske", "kind": "overrun",
         "partition": "io", "window": 0, "frame": 6248, "budget_ns": 4_000_000,
         "cause": "cpu_budget", "action": "stopped"},
        {"t_ns": 312_400_000_000, "node": "node1", "src": "ske", "kind": "overrun",
         "partition": "fdr", "window": 3, "frame": 6248, "cause": "outside_window",
         "action": "reported"},
        {"t_ns": 312_404_000_000, "node": "node1", "src": "ske", "kind": "hm",
         "partition": "io", "error": "WINDOW_OVERRUN", "level": "PARTITION", "action": "IGNORE"},
    ]
    trace = tmp_path / "node1.jsonl"
    trace.write_text("".join(json.dumps(x) + "\n" for x in lines) + '{"cut')
    hm, overruns = summary.node_events(trace)
    assert [e["error"] for e in hm] == ["WINDOW_OVERRUN"]
    assert overruns == [{"t_ns": 312_400_000_000, "partition": "io", "window": 0,
                         "budget_ns": 4_000_000}]  # the cause outside_window is not one
    cpu = [dict(o, node="node1") for o in overruns]
    host_stalls = summary.host_stalls
    assert host_stalls(cpu, set()) == cpu
    assert host_stalls(cpu, {("node1", "io")}) == []  # a fault on it explains it
    assert host_stalls(cpu, {("node1", None)}) == []  # so does one on the whole node
    assert host_stalls(cpu, {("node2", "io"), ("node1", "fdr")}) == cpu

    out = io.StringIO()
    report._print_host_stalls(cpu + cpu, 70, Console(file=out, width=200))  # 50 of 70 listed
    text = out.getvalue()
    assert "node1/io kept a window past its CPU budget at 312.400 s (and 69 more)" in text
    assert "host stalled it" in text
    out = io.StringIO()
    report._print_host_stalls([], 0, Console(file=out, width=200))
    assert out.getvalue() == ""

    # In a flight's summary: every overrun counted, the first 50 listed, stalls among all
    (tmp_path / "truth.jsonl").write_text(json.dumps({"t_ns": 0, "alt_ft": 3000}) + "\n")
    faulty = {"t_ns": 1, "node": "node1", "src": "ske", "kind": "overrun", "partition": "fdr",
              "window": 3, "budget_ns": 1, "cause": "cpu_budget", "action": "stopped"}
    trace.write_text("".join(json.dumps(dict(faulty, t_ns=k)) + "\n" for k in range(60))
                     + "".join(json.dumps(x) + "\n" for x in lines))
    s = summary.summarise(tmp_path, _script(tmp_path, []), 1.0, fault_targets={("node1", "fdr")})
    assert (s["cpu_overrun_count"], len(s["cpu_overruns"])) == (61, 50)
    assert s["host_stall_count"] == 1 and s["host_stalls"][0]["partition"] == "io"


@pytest.mark.parametrize("block", [1, 5, 64, 1 << 26])
def test_read_jsonl_finds_the_lines_with_a_needle_across_blocks(tmp_path, monkeypatch, block):
    """Lines found by searching the bytes, whatever the blocks the file is read in: in order,
    each once even with several needles in it; cut, garbled and non-UTF-8 lines skipped."""
    monkeypatch.setattr(summary, "READ_BLOCK", block)
    p = tmp_path / "t.jsonl"
    p.write_bytes(b'{"k":"hm","n":1}\n{"k":"x","n":2}\n\n{"k":"overrun hm","n":3}\r\n'
                  b'{"k":"hm", garbled\n{"k":"hm","s":"\xff"}\n[1, "hm"]\n{"k":"x","n":4}\n'
                  b'{"k":"hm","n":5}')  # the last line without its newline
    assert [r["n"] for r in summary.read_jsonl(p, "hm")] == [1, 3, 5]
    assert [r["n"] for r in summary.read_jsonl(p, ("overrun", "hm"))] == [1, 3, 5]
    assert [r["n"] for r in summary.read_jsonl(p)] == [1, 2, 3, 4, 5]
    assert list(summary.read_jsonl(p, "absent")) == []
    assert [r["n"] for r in summary.read_jsonl(p, ("", "absent"))] == [1, 2, 3, 4, 5]
    assert list(summary.read_jsonl(tmp_path / "missing.jsonl")) == []
