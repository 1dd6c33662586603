# SPDX-License-Identifier: Apache-2.0
"""The flown track's PNG and the run report's mission section, on run directories made here:
a flight along the small plan's path 20 m off it, with the mission manager's reports and a
C2 loss flown through its procedure and back; then runs with nothing to show (no reports, no
truth samples, a truth file cut short, a crash), which still give a PNG and no exception."""

from __future__ import annotations

import io
import json
import struct
import warnings
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

from ima.launch import report
from ima.mission import flown, geometry, plan, track

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
SPEED_MPS = 50.0
OFFSET_M = 20.0  # the flight is this far north of the planned path

# (t_s, text) of the mission manager; the image: 0 IF, 1 TF B, 2 HM, 3 TF C, 4 DF A (c2_loss)
REPORTS = [
    (0.03, "NO_PLAN leg -1 ?"),
    (0.5, "plan 7 active: 5 legs, crc 0x12345678"),
    (0.5, "STANDBY leg 1 TF"),
    (1.0, "ACTIVE leg 1 TF"),
    (30.0, "contingency c2_loss declared at leg 1"),
    (30.0, "CONTINGENCY leg 1 TF"),
    (40.0, "contingency c2_loss: procedure starts (mission leg 1 left)"),
    (40.0, "CONTINGENCY leg 4 DF"),
    (50.0, "contingency c2_loss cleared: mission resumes at leg 1"),
    (50.0, "ACTIVE leg 1 TF"),
    (80.0, "ACTIVE leg 3 TF"),
    (159.0, "mission complete"),
    (159.0, "COMPLETE leg 3 ORBIT"),
]


@pytest.fixture
def small(doc) -> plan.Plan:
    return plan.parse(doc, "small.yaml")


def _write_jsonl(path: Path, records: list[dict]) -> None:
    path.write_text("".join(json.dumps(r) + "\n" for r in records), encoding="utf-8")


def _node_trace(path: Path, reports: list[tuple[float, str]]) -> None:
    """A node's trace: the mission manager's reports among a few other records."""
    recs: list[dict] = [{"t_ns": 0, "node": "node1", "src": "ske", "kind": "module_start"}]
    for t_s, text in reports:
        recs.append({"t_ns": round(t_s * 1e9), "node": "node1", "src": "mission_manager",
                     "kind": "app_message", "process": 1, "text": f"mission_manager: {text}"})
        recs.append({"t_ns": round(t_s * 1e9), "node": "node1", "src": "ske",
                     "kind": "window_end", "partition": "mission_manager"})
    _write_jsonl(path, recs)


def _flight(p: plan.Plan) -> list[dict]:
    """Truth at 10 Hz along leg 1 (A to B) then leg 3 (B to C), OFFSET_M north of them."""
    paths = geometry.leg_paths(p)
    frame = geometry.Frame(p.origin_lat_deg, p.origin_lon_deg)
    route = np.concatenate([paths[1].points, paths[3].points[1:]])
    run = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(route, axis=0).T))])
    t = np.arange(0.0, run[-1] / SPEED_MPS, 0.1)
    s = t * SPEED_MPS
    north = np.interp(s, run, route[:, 0]) + OFFSET_M
    east = np.interp(s, run, route[:, 1])
    lat, lon = frame.to_geo(north, east)
    return [{"t_ns": round(ti * 1e9), "lat_deg": float(la), "lon_deg": float(lo),
             "alt_ft": 3000.0 + 5.0 * np.sin(ti / 7.0), "agl_ft": 2500.0,
             "airspeed_kt": 100.0 + np.cos(ti / 5.0), "gs_kt": 97.0}
            for ti, la, lo in zip(t, lat, lon, strict=True)]


def _run_dir(tmp_path: Path, p: plan.Plan) -> Path:
    run = tmp_path / "run"
    run.mkdir()
    _write_jsonl(run / "truth.jsonl", _flight(p))
    _node_trace(run / "node1.jsonl", REPORTS)
    (run / "world.json").write_text(json.dumps({"crashed": False, "reason": "end of the run"}))
    return run


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def _draw(run: Path, p: plan.Plan, judged: dict) -> Path:
    """write_track, failing on a TrackWarning (the fallback PNG)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", track.TrackWarning)
        return track.write_track(run, p, judged)


def _printed(summary: dict, fn=report.print_mission) -> str:
    out = io.StringIO()
    fn(summary, Console(file=out, width=160, color_system=None))
    return out.getvalue()


def test_the_track_of_a_flight_with_a_contingency(tmp_path, small):
    run = _run_dir(tmp_path, small)
    judged = flown.judge(run, small, "node1")
    assert [leg["index"] for leg in judged["legs"]] == [1, 3, 4]
    assert judged["contingencies"][0]["resumed_leg"] == 1
    path = _draw(run, small, judged)
    assert path == run / "track.png"
    width, height = _png_size(path)
    assert 800 <= width <= 1000 and 600 <= height <= 1600
    assert path.stat().st_size > 30_000  # a map and a profile, not an empty frame


def test_the_planned_altitude_follows_the_leg_being_flown(small):
    paths = geometry.leg_paths(small)
    msgs = [(round(t * 1e9), f"mission_manager: {text}") for t, text in REPORTS]
    ivs = flown.intervals(msgs, 160 * 10**9)
    t_ns = np.array([0.5, 10.0, 45.0, 60.0, 100.0, 159.5]) * 1e9
    alt = track.planned_altitude(small, paths, ivs, t_ns, np.zeros((len(t_ns), 2)))
    assert np.isnan(alt[0]) and np.isnan(alt[-1])  # STANDBY, COMPLETE: no leg flown
    assert alt[1:5] == pytest.approx([3000.0] * 4)
    states = track.sample_states(t_ns, ivs)
    assert list(states) == ["STANDBY", "ACTIVE", "CONTINGENCY", "ACTIVE", "ACTIVE", "COMPLETE"]


def test_the_report_prints_the_legs_and_the_contingencies(tmp_path, small):
    run = _run_dir(tmp_path, small)
    summary = flown.judge(run, small, "node1")
    summary["track_png"] = str(run / "track.png")
    text = _printed(summary)
    assert "Mission small (plan 7, node1's mission manager): COMPLETE at leg 3" in text
    assert "2/3 legs flown (and 1 of procedures)" in text
    for head in ("leg", "type", "time", "xte p95 / max", "alt err p95 / max", "airspeed",
                 "captured"):
        assert head in text, head
    rows = [line for line in text.splitlines() if "│" in line and " m " in line]
    assert [row.split("│")[1].strip() for row in rows] == ["TF", "TF", "DF"]
    leg1 = next(g for g in summary["legs"] if g["index"] == 1)
    assert f"{leg1['t_start_s']:.1f}–{leg1['t_end_s']:.1f} s" in text
    assert f"{leg1['xte_m_p95']:.1f} / {leg1['xte_m_max']:.1f} m" in text
    assert leg1["xte_m_max"] == pytest.approx(OFFSET_M, abs=1.0)
    assert "c2_loss" in text and "30.0 s (leg 1)" in text and "50.0 s" in text
    assert f"track: {run / 'track.png'}" in text


def test_the_run_report_shows_the_mission_only_for_a_mission(tmp_path, small):
    flight = {"run_dir": "RUN", "crashed": False, "flown_s": 160.0, "wall_s": 2.0,
              "speedup": 80.0, "alt_err_ft_max": None, "alt_err_ft_rms": None,
              "airspeed_err_kt_max": None, "airspeed_err_kt_rms": None,
              "heading_err_deg_max": None, "heading_err_deg_rms": None, "hold_segments": [],
              "bank_deg_max": 20.0, "mode_changes": [], "hm_events": 0, "hm_event_list": [],
              "nodes": ["node1"]}
    assert "Mission" not in _printed(flight, report.print_summary)
    run = _run_dir(tmp_path, small)
    summary = {**flight, **flown.judge(run, small, "node1"), "track_png": "RUN/track.png"}
    text = _printed(summary, report.print_summary)
    assert "Flight summary" in text and "Mission small" in text
    assert "track: RUN/track.png" in text


def test_no_reports_and_no_truth_still_give_a_png(tmp_path, small):
    run = tmp_path / "run"
    run.mkdir()
    (run / "truth.jsonl").write_text("")
    (run / "node1.jsonl").write_text("")
    judged = flown.judge(run, small, "node1")
    assert judged["legs"] == [] and judged["mission"]["final_state"] is None
    path = _draw(run, small, judged)
    assert _png_size(path)[0] > 0
    text = _printed(judged)
    assert "no state reported" in text and "No leg of the plan flown" in text
    assert "none declared" in text


def test_a_run_cut_short_and_crashed_still_gives_a_png(tmp_path, small):
    run = tmp_path / "run"
    run.mkdir()
    truth = "".join(json.dumps(r) + "\n" for r in _flight(small)[:300])
    (run / "truth.jsonl").write_text(truth + '{"t_ns": 30000000000, "lat_d')  # cut short
    (run / "world.json").write_text(json.dumps({"crashed": True, "crash_t_s": 29.9,
                                                "reason": "ground contact"}))
    # no node trace at all, and no judgement
    path = _draw(run, small, {})
    assert _png_size(path)[0] > 0
    _node_trace(run / "node1.jsonl", REPORTS[:6])
    with open(run / "node1.jsonl", "a", encoding="utf-8") as f:
        f.write('{"t_ns": 31000000000, "src": "mission_manager", "kind": "app_mess')
    assert _draw(run, small, {"contingencies": None}).exists()


def test_what_cannot_be_drawn_gives_a_png_that_says_so(tmp_path, small, monkeypatch):
    run = _run_dir(tmp_path, small)

    def broken(*args, **kwargs):
        raise ValueError("no good")

    monkeypatch.setattr(track, "_draw_track", broken)
    with pytest.warns(track.TrackWarning, match="no good"):
        path = track.write_track(run, small, {}, tmp_path / "out.png")
    assert path == tmp_path / "out.png" and _png_size(path)[0] > 0
