# SPDX-License-Identifier: Apache-2.0
"""Judges a flight from the world's truth trace: tracking errors over the autopilot hold
segments of the pilot script, bank, mode changes, bus load and health-monitor events."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ima.errors import ImaError

DEFAULT_SETTLE_S = 60.0
MODE_NAMES = {0: "INIT", 1: "DIRECT", 2: "AUTOPILOT", 3: "MISSION", 4: "CONTINGENCY"}
FALLBACK_NAMES = {0: "NONE", 1: "C2_LOST", 2: "MISSION_STALE", 3: "NAV_INVALID", 4: "NO_TARGETS",
                  5: "SENSOR_LOST"}  # as the DBC's FCS_FALLBACK value table


@dataclass(frozen=True)
class HoldSegment:
    """An interval where the aircraft should hold these autopilot targets (already settled)."""

    t0_s: float
    t1_s: float
    heading_deg: float
    altitude_ft: float
    airspeed_kt: float


def wrap180(deg: float) -> float:
    return (deg + 180.0) % 360.0 - 180.0


def hold_segments(pilot_yaml: Path, duration_s: float) -> list[HoldSegment]:
    """The pilot script's AUTOPILOT heading/altitude/airspeed holds with the C2 link up, each
    from `evaluate.settle_s` after its last change to the next change (or the end)."""
    from imaworld import pilot

    script = pilot.load(pilot_yaml)
    settle = DEFAULT_SETTLE_S if script.settle_s is None else float(script.settle_s)
    segments = []
    for t0, t1, tg in script.autopilot_segments(duration_s):
        if tg["lat_mode"] != "HDG" or tg["vert_mode"] != "ALT" or tg["c2_link"] != "up":
            continue
        if t0 + settle < t1:
            segments.append(HoldSegment(t0 + settle, t1, float(tg["heading_deg"]),
                                        float(tg["altitude_ft"]), float(tg["airspeed_kt"])))
    return segments


READ_BLOCK = 1 << 26  # read_jsonl reads this many bytes at a time (a 10-minute trace at once)


def read_jsonl(path: Path, needle: str | tuple[str, ...] | None = None) -> Iterator[dict]:
    """The JSON objects of a JSON-lines file; with `needle` (one string or several), only those
    of the lines that contain it. The others are neither parsed nor even split out: a node's
    trace is 200,000 lines an hour of which a summary wants a handful, found by searching the
    bytes. A line that is not a JSON object (cut by a killed writer, not UTF-8) is skipped."""
    try:
        f = path.open("rb")
    except FileNotFoundError:
        return
    needles = None if needle is None else \
        tuple(n.encode() for n in ((needle,) if isinstance(needle, str) else needle))
    if needles is not None and not all(needles):
        needles = None  # an empty needle is in every line
    with f:
        rest = b""
        while True:
            block = f.read(READ_BLOCK)
            data = rest + block
            if block:  # complete lines only; the last one may go on in the next block
                end = data.rfind(b"\n") + 1
                data, rest = data[:end], data[end:]
            for line in _lines(data, needles):
                line = line.strip()
                if not line:
                    continue
                try:
                    rec = json.loads(line)
                except ValueError:  # UnicodeDecodeError included
                    continue
                if isinstance(rec, dict):
                    yield rec
            if not block:
                return


def _lines(data: bytes, needles: tuple[bytes, ...] | None) -> list[bytes]:
    """The lines of `data` holding one of `needles` (all of them without needles), in order."""
    if needles is None:
        return data.split(b"\n")
    spans = set()
    for n in needles:
        i = data.find(n)
        while i >= 0:
            start = data.rfind(b"\n", 0, i) + 1
            end = data.find(b"\n", i)
            if end < 0:
                end = len(data)
            spans.add((start, end))
            i = data.find(n, end)
    return [data[s:e] for s, e in sorted(spans)]


def _read_json(path: Path) -> dict:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


class _Err:
    def __init__(self) -> None:
        self.n = 0
        self.sq = 0.0
        self.max = 0.0

    def add(self, e: float) -> None:
        self.n += 1
        self.sq += e * e
        self.max = max(self.max, abs(e))

    def rms(self) -> float | None:
        return math.sqrt(self.sq / self.n) if self.n else None


def tracking_errors(truth: Iterable[dict], segments: list[HoldSegment]) -> dict[str, Any]:
    alt, spd, hdg = _Err(), _Err(), _Err()
    bank_max = 0.0
    pitch_max = 0.0
    for rec in truth:
        t = rec.get("t_ns", 0) / 1e9
        roll = rec.get("roll_deg")
        if roll is not None:
            bank_max = max(bank_max, abs(roll))
        pitch = rec.get("pitch_deg")
        if pitch is not None:
            pitch_max = max(pitch_max, abs(pitch))
        for seg in segments:
            if seg.t0_s <= t < seg.t1_s:
                alt.add(rec["alt_ft"] - seg.altitude_ft)
                spd.add(rec["airspeed_kt"] - seg.airspeed_kt)
                hdg.add(wrap180(rec["heading_deg"] - seg.heading_deg))
                break
    rnd = lambda v, d=2: None if v is None else round(v, d)  # noqa: E731
    return {
        "alt_err_ft_max": rnd(alt.max if alt.n else None), "alt_err_ft_rms": rnd(alt.rms()),
        "airspeed_err_kt_max": rnd(spd.max if spd.n else None),
        "airspeed_err_kt_rms": rnd(spd.rms()),
        "heading_err_deg_max": rnd(hdg.max if hdg.n else None),
        "heading_err_deg_rms": rnd(hdg.rms()),
        "bank_deg_max": round(bank_max, 2), "pitch_deg_max": round(pitch_max, 2),
        "samples_judged": alt.n,
    }


def mode_changes(truth: Iterable[dict]) -> list[dict]:
    """The flight-control mode as the downlink reported it, each change once."""
    out = []
    last = (None, None)
    for rec in truth:
        cur = (rec.get("fcs_mode"), rec.get("fcs_fallback"))
        if cur != last and cur[0] is not None:
            out.append({"t_s": round(rec["t_ns"] / 1e9, 2), "mode": _name(MODE_NAMES, cur[0]),
                        "fallback": _name(FALLBACK_NAMES, cur[1])})
        last = cur
    return out


def _name(names: dict[int, str], v: Any) -> Any:
    return names.get(v, v) if isinstance(v, int) else v


def node_events(node_trace: Path) -> tuple[list[dict], list[dict]]:
    """A node's health-monitor events, and the windows its partitions kept past their CPU
    budget (the SKE's `overrun` events of cause `cpu_budget`), in one reading of its trace."""
    hm, overruns = [], []
    for rec in read_jsonl(node_trace, needle=('"hm"', '"overrun"')):
        kind = rec.get("kind")
        if kind == "hm":
            hm.append({k: rec.get(k)
                       for k in ("t_ns", "partition", "error", "level", "action", "process")})
        elif kind == "overrun" and rec.get("cause") == "cpu_budget":
            overruns.append({k: rec.get(k) for k in ("t_ns", "partition", "window", "budget_ns")})
    return hm, overruns


def host_stalls(overruns: list[dict], targets: set[tuple[str, str | None]]) -> list[dict]:
    """The CPU-budget overruns (node_events(), with their `node`) of partitions no fault acts on
    (`targets`: (node, partition), partition None for a whole node). The RPAS partitions use a
    small part of their budgets: one that overran was stalled by the host (a preempted virtual
    CPU, memory reclaim), not by anything in the run, and the flight from there is not a quiet
    host's."""
    return [o for o in overruns if (o["node"], o.get("partition")) not in targets
            and (o["node"], None) not in targets]


def summarise(run_dir: Path, pilot: Path, duration_s: float, wall_s: float | None = None,
              nodes: int = 1, plot: bool = False,
              events: list[tuple[float, str]] | None = None,
              fault_targets: set[tuple[str, str | None]] | None = None) -> dict[str, Any]:
    """The flight's summary (also written to RUN_DIR/summary.json); `plot` also draws
    RUN_DIR/flight.png, with `events` (time s, label) marked. `fault_targets`: what the run's
    faults act on (host_stalls())."""
    truth_path = run_dir / "truth.jsonl"
    truth = list(read_jsonl(truth_path))
    world = _read_json(run_dir / "world.json")
    bus = _read_json(run_dir / "canbus.json")
    segments = hold_segments(pilot, duration_s)
    summary: dict[str, Any] = {"run_dir": str(run_dir)}
    summary["crashed"] = bool(world.get("crashed", False))
    if summary["crashed"]:
        summary["crash"] = {"t_s": world.get("crash_t_s"), "reason": world.get("reason")}
    summary["flown_s"] = round(truth[-1]["t_ns"] / 1e9, 2) if truth else 0.0
    # a run cut short (Ctrl-C, crash) is judged on what it flew
    segments = [HoldSegment(g.t0_s, min(g.t1_s, summary["flown_s"]), g.heading_deg,
                            g.altitude_ft, g.airspeed_kt)
                for g in segments if g.t0_s < summary["flown_s"]]
    summary.update(tracking_errors(truth, segments))
    summary["hold_segments"] = [
        {"t0_s": s.t0_s, "t1_s": s.t1_s, "heading_deg": s.heading_deg,
         "altitude_ft": s.altitude_ft, "airspeed_kt": s.airspeed_kt} for s in segments]
    summary["mode_changes"] = mode_changes(truth)
    hm, overruns = [], []
    for k in range(1, nodes + 1):
        node_hm, node_overruns = node_events(run_dir / f"node{k}.jsonl")
        hm += [dict(ev, node=f"node{k}") for ev in node_hm]
        overruns += [dict(ev, node=f"node{k}") for ev in node_overruns]
    summary["hm_events"] = len(hm)
    summary["hm_event_list"] = hm[:50]
    overruns.sort(key=lambda e: (e["t_ns"] or 0, e["node"]))
    stalls = host_stalls(overruns, fault_targets or set())
    summary["cpu_overruns"], summary["cpu_overrun_count"] = overruns[:50], len(overruns)
    summary["host_stalls"], summary["host_stall_count"] = stalls[:50], len(stalls)
    summary["bus_load"] = bus.get("load")
    summary["bus_load_max_1s"] = bus.get("load_max_1s")
    summary["can_frames"] = bus.get("frames")
    summary["can_error_frames"] = bus.get("error_frames")
    if wall_s:
        summary["wall_s"] = round(wall_s, 2)
        summary["speedup"] = round(summary["flown_s"] / wall_s, 1) if wall_s > 0 else None
    if plot and truth:
        from ima.flight.plot import plot_flight

        try:
            summary["plot"] = str(plot_flight(truth, segments, run_dir / "flight.png",
                                              f"{pilot.name}, {run_dir.name}", events))
        except OSError as exc:  # a full disk: the summary says so, the run is not lost
            summary["plot"] = None
            summary["plot_error"] = f"{run_dir / 'flight.png'}: {exc.strerror}"
    write_summary(run_dir, summary)
    return summary


def write_summary(run_dir: Path, summary: dict) -> None:
    """RUN_DIR/summary.json; ImaError when it cannot be written (the traces stay)."""
    path = run_dir / "summary.json"
    try:
        path.write_text(json.dumps(summary, indent=2) + "\n")
    except OSError as exc:
        raise ImaError(f"cannot write {path}: {exc.strerror} (the run's traces are in "
                       f"{run_dir})") from exc
