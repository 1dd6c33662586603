# SPDX-License-Identifier: Apache-2.0
"""A flown mission judged on the truth: which leg the mission manager flew when (its reports
in the node's trace), how far the aircraft really was from each leg's planned path and
altitude (truth.jsonl against ima.mission.geometry), the contingencies it declared, their
procedures and the mission's resumption, and the landing.

Leg statistics count from the leg's capture: the first truth sample within CAPTURE_M of the
planned path with the track within CAPTURE_DEG of the path's course there (a leg begins where
the turn from the previous one begins, off its path, and may cross it while turning: the
aircraft is established once close and aligned). A hold is judged on its racetrack, once the
mission manager reports the entry flown. CA and VA have no path of their own (a course or a
heading until an altitude): they are judged on their terminator. A scan is judged pass by
pass: the samples flying along a pass (within 30 degrees of its course, beside it by less
than half the spacing, between its ends), each pass from its own capture. The altitude is
judged where the plan holds one (a level leg, a geometric path) from the first
sample within CAPTURE_ALT_M of it; a climb or descent at constant airspeed is judged after it
has levelled off at the constraint."""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ima.mission.geometry import FT, Frame, LegPath, leg_paths
from ima.mission.plan import Plan

CAPTURE_M = 15.0
CAPTURE_DEG = 10.0
_RACETRACK = re.compile(r"mission_manager: leg (\d+) hold: (\w+) entry flown")
PASS_TRACK_DEG = 30.0
AUTOLAND_JUDGED_ABOVE_FT = 50.0
NEXT_LEG_NS = 60 * 10**9  # a fix is passed within the next leg's first minute (fly-by)
CAPTURE_ALT_M = 15.0
_STATE = re.compile(r"mission_manager: ([A-Z_]+) leg (-?\d+) (\S+)$")
_DECLARED = re.compile(r"mission_manager: contingency (\w+) declared at leg (-?\d+)$")
_STARTS = re.compile(r"mission_manager: contingency (\w+): procedure starts")
_CLEARED = re.compile(r"mission_manager: contingency (\w+) cleared: mission resumes at leg (\d+)")


@dataclass
class Interval:
    t0_ns: int
    t1_ns: int
    state: str
    leg: int
    type: str


def reports(trace: Path) -> list[tuple[int, str]]:
    """The mission manager's reports in a node's trace: [(t_ns, text)]."""
    out: list[tuple[int, str]] = []
    if not Path(trace).is_file():
        return out
    with open(trace, encoding="utf-8", errors="replace") as f:
        for line in f:
            if '"mission_manager"' not in line or '"app_message"' not in line:
                continue
            rec = _record(line)
            if rec and rec.get("kind") == "app_message" and rec.get("src") == "mission_manager":
                out.append((int(rec.get("t_ns", 0)), str(rec.get("text", ""))))
    return out


def _record(line: str) -> dict | None:
    """A JSON line, or None for a line cut short (a run killed while it wrote)."""
    try:
        rec = json.loads(line)
    except ValueError:
        return None
    return rec if isinstance(rec, dict) else None


def intervals(msgs: list[tuple[int, str]], end_ns: int) -> list[Interval]:
    """The mission manager's state and leg, piecewise constant until end_ns."""
    out: list[Interval] = []
    for t, text in msgs:
        m = _STATE.match(text)
        if not m:
            continue
        if out:
            out[-1].t1_ns = t
        out.append(Interval(t, end_ns, m.group(1), int(m.group(2)), m.group(3)))
    return [iv for iv in out if iv.t1_ns > iv.t0_ns]


def procedure_text(plan: Plan | None, event: str) -> str | None:
    """What the plan does for a contingency: "DF RALLY, HM RALLY", "hold", "avoid 60 deg,
    500 ft", "terminate" (None: not in the plan)."""
    c = plan.contingencies.get(event) if plan is not None else None
    if c is None:
        return None
    if c.action == "procedure":
        return ", ".join(f"{leg.type} {leg.fix or leg.runway or ''}".strip()
                         for leg in c.procedure)
    if c.action == "avoid":
        return f"avoid {c.offset_deg:g} deg, {c.altitude_offset_ft:g} ft"
    return c.action


def contingencies(msgs: list[tuple[int, str]], plan: Plan | None = None) -> list[dict]:
    """Each contingency: when it was declared, the procedure the plan gives for it and when it
    began, the mission's resumption."""
    out: list[dict] = []
    for t, text in msgs:
        if m := _DECLARED.match(text):
            out.append({"event": m.group(1), "t_s": t / 1e9, "leg": int(m.group(2)),
                        "procedure": procedure_text(plan, m.group(1)),
                        "procedure_t_s": None, "resumed_t_s": None, "resumed_leg": None})
        elif (m := _STARTS.match(text)) and out and out[-1]["event"] == m.group(1):
            out[-1]["procedure_t_s"] = t / 1e9
        elif (m := _CLEARED.match(text)) and out and out[-1]["event"] == m.group(1):
            out[-1]["resumed_t_s"] = t / 1e9
            out[-1]["resumed_leg"] = int(m.group(2))
    return out


def load_truth(path: Path) -> dict[str, np.ndarray]:
    cols = ("t_ns", "lat_deg", "lon_deg", "alt_ft", "agl_ft", "airspeed_kt", "gs_kt", "track_deg")
    rows = []
    if Path(path).is_file():
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                r = _record(line)
                if r is not None and isinstance(r.get("t_ns"), int):
                    rows.append([r.get(c) if isinstance(r.get(c), (int, float)) else np.nan
                                 for c in cols])
    a = np.array(rows, dtype=float).reshape(-1, len(cols))
    return {c: a[:, i] for i, c in enumerate(cols)}


def _along(points: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The distance along a polyline (from its first point) of each position's nearest point."""
    if len(points) < 2:
        return np.zeros(len(q))
    a, b = points[:-1], points[1:]
    ab = b - a
    seg = np.hypot(*ab.T)
    start = np.concatenate([[0.0], np.cumsum(seg)[:-1]])
    den = np.maximum((ab * ab).sum(axis=1), 1e-12)
    t = np.clip(((q[:, None, :] - a) * ab).sum(axis=2) / den, 0.0, 1.0)
    near = a + t[..., None] * ab
    d = np.hypot(*(q[:, None, :] - near).transpose(2, 0, 1))
    k = d.argmin(axis=1)
    return start[k] + t[np.arange(len(q)), k] * seg[k]


def _course_err(points: np.ndarray, q: np.ndarray, track_deg: np.ndarray) -> np.ndarray:
    """|track - the course of the polyline's nearest segment| (deg) of each position."""
    if len(points) < 2 or not len(q):
        return np.zeros(len(q))
    a, b = points[:-1], points[1:]
    ab = b - a
    den = np.maximum((ab * ab).sum(axis=1), 1e-12)
    t = np.clip(((q[:, None, :] - a) * ab).sum(axis=2) / den, 0.0, 1.0)
    near = a + t[..., None] * ab
    k = np.hypot(*(q[:, None, :] - near).transpose(2, 0, 1)).argmin(axis=1)
    crs = np.degrees(np.arctan2(ab[k, 1], ab[k, 0]))
    return np.abs((track_deg - crs + 180.0) % 360.0 - 180.0)


def _p95(x: np.ndarray) -> float | None:
    return round(float(np.percentile(x, 95)), 2) if len(x) else None


def _max(x: np.ndarray) -> float | None:
    return round(float(np.max(x)), 2) if len(x) else None


def pass_stats(path: LegPath, ne: np.ndarray, track_deg: np.ndarray) -> list[dict]:
    """A scan's passes, each judged on the samples flying along it, from its capture."""
    out = []
    spacing = (float(np.hypot(*(path.passes[1][0] - path.passes[0][1])))
               if len(path.passes) > 1 else 400.0)
    for k, (a, b) in enumerate(path.passes):
        u = (b - a) / max(float(np.hypot(*(b - a))), 1e-9)
        rel = ne - a
        along = rel @ u
        across = rel @ np.array([-u[1], u[0]])
        crs = np.degrees(np.arctan2(u[1], u[0]))
        aligned = np.abs((track_deg - crs + 180.0) % 360.0 - 180.0) <= PASS_TRACK_DEG
        on = aligned & (np.abs(across) < spacing / 2) & (along >= 0.0) & \
            (along <= float(np.hypot(*(b - a))))
        x = np.abs(across[on])
        cap = np.flatnonzero(x <= CAPTURE_M)
        after = x[cap[0]:] if len(cap) else x
        out.append({"pass": k, "samples": int(on.sum()), "captured": bool(len(cap)),
                    "xte_m_p95": _p95(after), "xte_m_max": _max(after)})
    return out


def leg_stats(path: LegPath, geometric: bool, ne: np.ndarray, alt_ft: np.ndarray,
              ias: np.ndarray, t_ns: np.ndarray, track_deg: np.ndarray | None = None) -> dict:
    """One leg's accuracy over its samples (ne: local positions); `geometric`: its altitude
    is a geometric path (else a climb or descent is judged once levelled off)."""
    xte = path.distance_to(ne) if len(ne) else np.zeros(0)
    aligned = (_course_err(path.points, ne, track_deg) <= CAPTURE_DEG
               if track_deg is not None else np.ones(len(ne), bool))
    cap = np.flatnonzero((xte <= CAPTURE_M) & aligned)
    captured = len(cap) > 0
    after = xte[cap[0]:] if captured else xte
    # the planned altitude: the profile along the leg proper (the entry is not flown as such)
    if geometric and len(ne):
        ref = path.altitude_at(path.entry_m + _along(path.points, ne))
    else:
        ref = np.full(len(ne), path.altitude_ft)
    err_m = np.abs(alt_ft - ref) * FT if len(ne) else np.zeros(0)
    acap = np.flatnonzero(err_m <= CAPTURE_ALT_M)
    alt_after = err_m[acap[0]:] if len(acap) else np.zeros(0)
    passes = None
    if path.type == "SCAN" and len(path.passes) and track_deg is not None:
        passes = pass_stats(path, ne, track_deg)
        flown_passes = [p for p in passes if p["xte_m_p95"] is not None]
        if flown_passes:
            after = np.array([max(p["xte_m_p95"] for p in flown_passes)])
            xmax = max(p["xte_m_max"] for p in flown_passes)
            captured = all(p["captured"] for p in passes)
    out = {
        "index": path.index, "type": path.type, "label": path.label,
        "t_start_s": round(t_ns[0] / 1e9, 2) if len(t_ns) else None,
        "t_end_s": round(t_ns[-1] / 1e9, 2) if len(t_ns) else None,
        "samples": int(len(ne)), "captured": captured,
        "xte_m_p95": _p95(after), "xte_m_max": _max(after),
        "alt_err_m_p95": _p95(alt_after), "alt_err_m_max": _max(alt_after),
        "ias_kt_min": round(float(np.nanmin(ias)), 1) if len(ias) else None,
        "ias_kt_max": round(float(np.nanmax(ias)), 1) if len(ias) else None,
    }
    if passes is not None:
        out["passes"] = passes
        if flown_passes:
            out["xte_m_p95"], out["xte_m_max"] = round(float(after[0]), 2), xmax
    # no path: a course (CA) or a heading (VA) to an altitude; a procedure's direct-to from
    # wherever the aircraft is (its planned path is its fix alone)
    if path.type in ("CA", "VA") or len(path.points) < 2:
        out["xte_m_p95"] = out["xte_m_max"] = None
        out["captured"] = None
    return out


def terminator(path: LegPath, leg, ne: np.ndarray, alt_ft: np.ndarray, track_deg: np.ndarray,
               fix_ne: np.ndarray | None) -> dict:
    """Where the leg ended against its terminator: the altitude reached (CA, FA, VA, HA), the
    fix passed (the closest the aircraft came to it, over the leg and the next one's first
    minute: a fly-by turn passes inside it), the course at the end (CF, DUBINS)."""
    out: dict = {}
    if not len(ne):
        return out
    if path.type in ("CA", "FA", "VA", "HA") and leg.altitude_ft is not None:
        out["end_alt_err_ft"] = round(float(alt_ft[-1] - leg.altitude_ft), 1)
    if fix_ne is not None and path.type in ("TF", "DF", "CF", "RF", "DIRECT", "DUBINS"):
        out["fix_miss_m"] = round(float(np.min(np.hypot(*(ne - fix_ne).T))), 1)
    if path.type in ("CF", "DUBINS") and path.end_course_deg is not None:
        out["end_course_err_deg"] = round(float(abs((track_deg[-1] - path.end_course_deg + 180.0)
                                                    % 360.0 - 180.0)), 1)
    return out


def world_events(run_dir: Path, kinds: set[str]) -> list[dict]:
    out = []
    path = Path(run_dir) / "world.jsonl"
    if not path.is_file():
        return out
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            rec = _record(line)
            if rec is not None and rec.get("kind") in kinds:
                out.append(rec)
    return out


def autoland(run_dir: Path, plan: Plan, frame) -> dict | None:
    """The landing on the plan's AUTOLAND runway, from the world's gear events: where the
    main wheels touched against the aim point (+ beyond it) and the centre line, the sink
    rate, bounces, and where (whether) the aircraft stopped on the runway. None: the plan has
    no landing."""
    leg = next((lg for lg in plan.legs if lg.type == "AUTOLAND"), None)
    if leg is None:
        return None
    rw = plan.runways[leg.runway]
    thr = frame.to_local(rw.lat_deg, rw.lon_deg)
    u = np.array([math.cos(math.radians(rw.heading_deg)), math.sin(math.radians(rw.heading_deg))])
    right = np.array([-u[1], u[0]])

    def where(ev: dict) -> tuple[float, float]:
        d = frame.to_local(ev["lat_deg"], ev["lon_deg"]) - thr
        return float(d @ u), float(d @ right)

    ev = world_events(run_dir, {"touchdown", "bounce", "stopped", "crash"})
    td = next((e for e in ev if e["kind"] == "touchdown"), None)
    stop = next((e for e in ev if e["kind"] == "stopped"), None)
    crash = next((e for e in ev if e["kind"] == "crash"), None)
    out = {"runway": rw.name, "landed": td is not None, "crashed": crash is not None,
           "crash_reason": crash.get("reason") if crash else None,
           "touchdown_t_s": None, "touchdown_from_aim_m": None, "centerline_m": None,
           "sink_fps": None, "bounced": any(e["kind"] == "bounce" for e in ev),
           "stopped": stop is not None, "stop_from_threshold_m": None,
           "stopped_on_runway": False}
    if td is not None:
        along, across = where(td)
        out.update(touchdown_t_s=round(td["t_ns"] / 1e9, 2),
                   touchdown_from_aim_m=round(along - rw.aim_point_m, 1),
                   centerline_m=round(abs(across), 2), sink_fps=td["sink_fps"])
    if stop is not None:
        along, across = where(stop)
        out["stop_from_threshold_m"] = round(along, 1)
        out["stopped_on_runway"] = bool(0.0 <= along <= rw.length_m and
                                        abs(across) <= rw.width_m / 2)
    return out


def judge(run_dir: Path, plan: Plan, node: str) -> dict:
    """The summary's `mission`, `legs` and `contingencies` of a run flown with `plan`, from
    `node`'s mission manager (every replica flies the same)."""
    run_dir = Path(run_dir)
    truth = load_truth(run_dir / "truth.jsonl")
    t = truth["t_ns"]
    end = int(t[-1]) + 1 if len(t) else 0
    msgs = reports(run_dir / f"{node}.jsonl")
    ivs = intervals(msgs, end)
    paths = leg_paths(plan)
    frame = Frame(plan.origin_lat_deg, plan.origin_lon_deg)
    ne_all = frame.to_local(truth["lat_deg"], truth["lon_deg"]) if len(t) else np.zeros((0, 2))
    legs = []
    n_mission = len(plan.legs)
    by_index = {p.index: p for p in paths}
    geometric = {i: leg.geometric or leg.type == "AUTOLAND"
                 for i, (leg, _) in enumerate(plan.image_legs())}
    flown: dict[int, np.ndarray] = {}
    for iv in ivs:
        if iv.state not in ("ACTIVE", "CONTINGENCY") or iv.leg not in by_index:
            continue
        if iv.type != by_index[iv.leg].type:
            continue  # a leg made up in flight (a hold, a direct-to) on the leg's number
        mask = (t >= iv.t0_ns) & (t < iv.t1_ns)
        flown[iv.leg] = mask if iv.leg not in flown else flown[iv.leg] | mask
    racetrack = {}
    for tr_ns, text in msgs:
        if (mt := _RACETRACK.match(text)) and int(mt.group(1)) not in racetrack:
            racetrack[int(mt.group(1))] = tr_ns
    image_legs = [leg for leg, _ in plan.image_legs()]
    for idx in sorted(flown):
        m = flown[idx]
        path, leg = by_index[idx], image_legs[idx]
        whole = m
        if path.type == "AUTOLAND":  # the touchdown criteria judge below 50 ft
            m = m & (truth["agl_ft"] >= AUTOLAND_JUDGED_ABOVE_FT)
        if path.type in ("HA", "HF", "HM"):  # the racetrack, once the entry is flown
            m = m & (t >= racetrack.get(idx, np.inf))
        stats = leg_stats(path, geometric[idx], ne_all[m], truth["alt_ft"][m],
                          truth["airspeed_kt"][m], t[m], truth["track_deg"][m])
        if path.type in ("HA", "HF", "HM"):
            stats["entry"] = next((tx.split("hold: ")[1].split(" ")[0] for tn, tx in msgs
                                   if tn == racetrack.get(idx) and "hold:" in tx), None)
        # the terminator: over the leg and, for a fix, the next leg's first minute
        k = np.flatnonzero(whole)
        ext = whole.copy()
        if len(k):
            ext[k[-1]:] = t[k[-1]:] <= t[k[-1]] + NEXT_LEG_NS
        fix_ne = (frame.to_local(plan.waypoints[leg.fix].lat_deg, plan.waypoints[leg.fix].lon_deg)
                  if leg.fix in plan.waypoints else None)
        stats.update(terminator(path, leg, ne_all[ext if fix_ne is not None else whole],
                                truth["alt_ft"][whole], truth["track_deg"][whole], fix_ne))
        legs.append(stats)
    final = ivs[-1] if ivs else None
    return {
        "mission": {"plan": plan.name, "plan_id": plan.plan_id, "node": node,
                    "legs_planned": sum(1 for leg in plan.legs if leg.type != "IF"),
                    "legs_flown": sum(1 for lg in legs if lg["index"] < n_mission),
                    "procedure_legs_flown": sum(1 for lg in legs if lg["index"] >= n_mission),
                    "final_state": final.state if final else None,
                    "final_leg": final.leg if final else None},
        "legs": legs,
        "contingencies": contingencies(msgs, plan),
        "autoland": autoland(run_dir, plan, frame),
    }
