# SPDX-License-Identifier: Apache-2.0
"""A flown mission judged on the truth: which leg the mission manager flew when (its reports
in the node's trace), how far the aircraft really was from each leg's planned path and
altitude (truth.jsonl against ima.mission.geometry), the contingencies it declared, their
procedures and the mission's resumption, and the landing.

Leg statistics count from the leg's capture: the first truth sample within CAPTURE_M of the
planned path (a leg begins where the turn from the previous one begins, off its path). The
altitude is judged where the plan holds one (a level leg, a geometric path) from the first
sample within CAPTURE_ALT_M of it; a climb or descent at constant airspeed is judged after it
has levelled off at the constraint."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ima.mission.geometry import FT, LegPath, leg_paths
from ima.mission.plan import Plan

CAPTURE_M = 50.0
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
    out = []
    with open(trace, encoding="utf-8") as f:
        for line in f:
            if '"mission_manager"' not in line or '"app_message"' not in line:
                continue
            rec = json.loads(line)
            if rec.get("kind") == "app_message" and rec.get("src") == "mission_manager":
                out.append((rec["t_ns"], rec.get("text", "")))
    return out


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


def contingencies(msgs: list[tuple[int, str]]) -> list[dict]:
    """Each contingency: when it was declared, its procedure's start, the mission's resumption."""
    out: list[dict] = []
    for t, text in msgs:
        if m := _DECLARED.match(text):
            out.append({"event": m.group(1), "t_s": t / 1e9, "leg": int(m.group(2)),
                        "procedure": None, "procedure_t_s": None, "resumed_t_s": None,
                        "resumed_leg": None})
        elif (m := _STARTS.match(text)) and out and out[-1]["event"] == m.group(1):
            out[-1]["procedure_t_s"] = t / 1e9
        elif (m := _CLEARED.match(text)) and out and out[-1]["event"] == m.group(1):
            out[-1]["resumed_t_s"] = t / 1e9
            out[-1]["resumed_leg"] = int(m.group(2))
    return out


def load_truth(path: Path) -> dict[str, np.ndarray]:
    cols = ("t_ns", "lat_deg", "lon_deg", "alt_ft", "agl_ft", "airspeed_kt", "gs_kt")
    rows = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            r = json.loads(line)
            rows.append([r.get(c) if r.get(c) is not None else np.nan for c in cols])
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


def _p95(x: np.ndarray) -> float | None:
    return round(float(np.percentile(x, 95)), 2) if len(x) else None


def _max(x: np.ndarray) -> float | None:
    return round(float(np.max(x)), 2) if len(x) else None


def leg_stats(path: LegPath, geometric: bool, ne: np.ndarray, alt_ft: np.ndarray,
              ias: np.ndarray, t_ns: np.ndarray) -> dict:
    """One leg's accuracy over its samples (ne: local positions); `geometric`: its altitude
    is a geometric path (else a climb or descent is judged once levelled off)."""
    xte = path.distance_to(ne) if len(ne) else np.zeros(0)
    cap = np.flatnonzero(xte <= CAPTURE_M)
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
    return {
        "index": path.index, "type": path.type, "label": path.label,
        "t_start_s": round(t_ns[0] / 1e9, 2) if len(t_ns) else None,
        "t_end_s": round(t_ns[-1] / 1e9, 2) if len(t_ns) else None,
        "samples": int(len(ne)), "captured": captured,
        "xte_m_p95": _p95(after), "xte_m_max": _max(after),
        "alt_err_m_p95": _p95(alt_after), "alt_err_m_max": _max(alt_after),
        "ias_kt_min": round(float(np.nanmin(ias)), 1) if len(ias) else None,
        "ias_kt_max": round(float(np.nanmax(ias)), 1) if len(ias) else None,
    }


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
    from ima.mission.geometry import Frame

    frame = Frame(plan.origin_lat_deg, plan.origin_lon_deg)
    ne_all = frame.to_local(truth["lat_deg"], truth["lon_deg"]) if len(t) else np.zeros((0, 2))
    legs = []
    by_index = {p.index: p for p in paths}
    geometric = {i: leg.geometric for i, (leg, _) in enumerate(plan.image_legs())}
    flown: dict[int, np.ndarray] = {}
    for iv in ivs:
        if iv.state not in ("ACTIVE", "CONTINGENCY") or iv.leg not in by_index:
            continue
        if iv.type != by_index[iv.leg].type:
            continue  # a leg made up in flight (a hold, a direct-to) on the leg's number
        mask = (t >= iv.t0_ns) & (t < iv.t1_ns)
        flown[iv.leg] = mask if iv.leg not in flown else flown[iv.leg] | mask
    for idx in sorted(flown):
        m = flown[idx]
        legs.append(leg_stats(by_index[idx], geometric[idx], ne_all[m], truth["alt_ft"][m],
                              truth["airspeed_kt"][m], t[m]))
    final = ivs[-1] if ivs else None
    return {
        "mission": {"plan": plan.name, "plan_id": plan.plan_id, "node": node,
                    "legs_planned": sum(1 for p in paths if p.procedure is None),
                    "legs_flown": len(legs),
                    "final_state": final.state if final else None,
                    "final_leg": final.leg if final else None},
        "legs": legs,
        "contingencies": contingencies(msgs),
    }
