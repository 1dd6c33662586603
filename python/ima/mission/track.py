# SPDX-License-Identifier: Apache-2.0
"""A flown mission in one PNG, RUN_DIR/track.png: the plan's map (ima.mission.plot.draw_plan)
with the ground track the aircraft really flew (truth.jsonl) over it, coloured by the mission
manager's state, its contingencies marked where they were declared, where their procedure
started and where the mission resumed; under it the flown altitude against time with the
planned altitude of the leg being flown, the leg boundaries and the contingencies shaded.

A run whose plan never became active, a truth file cut short or a crashed aircraft still give
a plot, with a note of what is missing."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np

from ima.mission import flown
from ima.mission.geometry import Frame, LegPath, leg_paths
from ima.mission.plan import Plan
from ima.mission.plot import draw_plan, extent_points, map_height_in

FLYING = ("ACTIVE", "CONTINGENCY")  # the states in which the mission manager flies a leg
STATE_COLOURS = {"ACTIVE": "black", "CONTINGENCY": "magenta"}
OTHER_COLOUR = "darkgray"  # STANDBY, PAUSED, COMPLETE, ..., or no report at all
NO_REPORT = "no report"
# a contingency's events: its key in the summary, the map's marker and colour, the name
CONTINGENCY_EVENTS = (("t_s", "X", "tab:red", "declared"),
                      ("procedure_t_s", "s", "tab:orange", "procedure starts"),
                      ("resumed_t_s", "o", "tab:green", "mission resumes"))
_TRUTH_COLUMNS = ("t_ns", "lat_deg", "lon_deg", "alt_ft", "agl_ft")


class TrackWarning(UserWarning):
    """The track could not be drawn in full; the PNG written instead says why."""


def _number(value) -> float:
    """A JSON value as a float; NaN for anything else (null, a string)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return math.nan
    return float(value)


def read_truth(path: Path) -> tuple[dict[str, np.ndarray], int, bool]:
    """The truth trace's columns (t_ns, lat_deg, lon_deg, alt_ft, agl_ft; NaN where a sample
    lacks one), how many lines could not be read (a file cut short) and whether it exists."""
    rows: list[list[float]] = []
    bad = 0
    try:
        f = open(path, encoding="utf-8", errors="replace")
    except OSError:
        return _columns(rows), 0, False
    with f:
        for line in f:
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
                t = _number(rec["t_ns"])
            except (ValueError, KeyError, TypeError):
                bad += 1
                continue
            if math.isnan(t):
                bad += 1
                continue
            rows.append([t] + [_number(rec.get(c)) for c in _TRUTH_COLUMNS[1:]])
    return _columns(rows), bad, True


def _columns(rows: list[list[float]]) -> dict[str, np.ndarray]:
    a = np.array(rows, dtype=float).reshape(-1, len(_TRUTH_COLUMNS))
    return {c: a[:, i] for i, c in enumerate(_TRUTH_COLUMNS)}


def read_reports(trace: Path) -> tuple[list[tuple[int, str]], bool]:
    """The mission manager's reports in a node's trace, as flown.reports reads them but
    skipping what cannot be read (a line cut short); and whether the trace exists."""
    out: list[tuple[int, str]] = []
    try:
        f = open(trace, encoding="utf-8", errors="replace")
    except OSError:
        return out, False
    with f:
        for line in f:
            if '"mission_manager"' not in line or '"app_message"' not in line:
                continue
            try:
                rec = json.loads(line)
            except ValueError:
                continue
            if isinstance(rec, dict) and rec.get("kind") == "app_message" and \
                    rec.get("src") == "mission_manager" and isinstance(rec.get("t_ns"), int):
                out.append((rec["t_ns"], str(rec.get("text", ""))))
    return out, True


def _read_json(path: Path) -> dict | None:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None


def sample_states(t_ns: np.ndarray, ivs: list[flown.Interval]) -> np.ndarray:
    """The mission manager's state at each truth sample (NO_REPORT outside its reports)."""
    out = np.full(len(t_ns), NO_REPORT, dtype=object)
    if not ivs or not len(t_ns):
        return out
    t0 = np.array([iv.t0_ns for iv in ivs], dtype=float)
    t1 = np.array([iv.t1_ns for iv in ivs], dtype=float)
    k = np.searchsorted(t0, t_ns, side="right") - 1
    inside = (k >= 0) & (t_ns < t1[np.maximum(k, 0)])
    names = np.array([iv.state for iv in ivs], dtype=object)
    out[inside] = names[k[inside]]
    return out


def planned_altitude(plan: Plan, paths: list[LegPath], ivs: list[flown.Interval],
                     t_ns: np.ndarray, ne: np.ndarray) -> np.ndarray:
    """The planned altitude (ft) of the leg being flown at each truth sample: the leg's
    altitude_ft, or on a geometric path its profile where the aircraft is along it; NaN when
    no leg of the plan is flown (no report, a hold or direct-to made up in flight)."""
    out = np.full(len(t_ns), np.nan)
    by_index = {p.index: p for p in paths}
    geometric = {i: leg.geometric or leg.type == "AUTOLAND"  # the glide path
                 for i, (leg, _) in enumerate(plan.image_legs())}
    for iv in ivs:
        path = by_index.get(iv.leg)
        if iv.state not in FLYING or path is None or iv.type != path.type:
            continue
        m = (t_ns >= iv.t0_ns) & (t_ns < iv.t1_ns)
        if geometric.get(iv.leg):
            m &= np.isfinite(ne).all(axis=1)
            if m.any():
                out[m] = path.altitude_at(path.entry_m + flown._along(path.points, ne[m]))
        else:
            out[m] = path.altitude_ft
    return out


def _position_at(t_s: np.ndarray, ne: np.ndarray, when: float) -> np.ndarray | None:
    """Where (north, east m) the aircraft was at `when` (s); None without a position then."""
    ok = np.isfinite(ne).all(axis=1)
    if not ok.any() or when < t_s[ok][0] - 1.0 or when > t_s[ok][-1] + 1.0:
        return None
    return np.array([np.interp(when, t_s[ok], ne[ok, 0]), np.interp(when, t_s[ok], ne[ok, 1])])


def _runs(values: np.ndarray) -> list[tuple[int, int]]:
    """The [start, end) index ranges over which `values` stays the same."""
    if not len(values):
        return []
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    bounds = [0, *change.tolist(), len(values)]
    return list(zip(bounds[:-1], bounds[1:], strict=True))


def _notes(node: str, n_truth: int, bad: int, have_truth: bool,
           msgs: list, have_trace: bool, ivs: list[flown.Interval],
           world: dict | None) -> list[str]:
    """What the plot lacks, and why, in a few words each."""
    notes = []
    if not have_truth:
        notes.append("truth.jsonl missing: no flown track")
    elif not n_truth:
        notes.append("truth.jsonl has no samples: no flown track")
    if bad:
        notes.append(f"truth.jsonl: {bad} unreadable line(s) skipped (cut short?)")
    if not have_trace:
        notes.append(f"{node}.jsonl missing: no mission manager reports")
    elif not msgs:
        notes.append(f"no mission manager reports in {node}.jsonl")
    elif not any(iv.state in FLYING for iv in ivs):
        seen = ", ".join(dict.fromkeys(iv.state for iv in ivs)) or "none"
        notes.append(f"the plan never became active (states reported: {seen})")
    if world is None:
        notes.append("world.json missing: the world did not end the run")
    elif world.get("crashed"):
        at = world.get("crash_t_s")
        when = f" at {at:.1f} s" if isinstance(at, (int, float)) else ""
        notes.append(f"the aircraft crashed{when} ({world.get('reason') or 'no reason given'})")
    return notes


def legs_flown(paths: list[LegPath], judged: dict) -> str:
    """"4/5 legs flown" (the mission's legs after its IF), and the procedures' legs flown."""
    mission = {p.index for p in paths if p.procedure is None and p.type != "IF"}
    done = {leg.get("index") for leg in judged.get("legs") or []}
    text = f"{len(done & mission)}/{len(mission)} legs flown"
    extra = len(done - mission)
    return text + (f" (and {extra} of procedures)" if extra else "")


def _draw(run_dir: Path, plan: Plan, judged: dict, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = leg_paths(plan)
    frame = Frame(plan.origin_lat_deg, plan.origin_lon_deg)
    mission = judged.get("mission") or {}
    node = str(mission.get("node") or "node1")
    truth, bad, have_truth = read_truth(run_dir / "truth.jsonl")
    msgs, have_trace = read_reports(run_dir / f"{node}.jsonl")
    t_ns = truth["t_ns"]
    t_s = t_ns / 1e9
    last_ns = max([int(t_ns[-1]) if len(t_ns) else 0] + [t for t, _ in msgs])
    ivs = flown.intervals(msgs, last_ns + 1)
    conts = judged.get("contingencies")
    if conts is None:
        conts = flown.contingencies(msgs)
    ne = frame.to_local(truth["lat_deg"], truth["lon_deg"]) if len(t_ns) else np.zeros((0, 2))
    states = sample_states(t_ns, ivs)
    world = _read_json(run_dir / "world.json")
    notes = _notes(node, len(t_ns), bad, have_truth, msgs, have_trace, ivs, world)
    crashed = bool(world and world.get("crashed"))

    shown = np.concatenate([extent_points(plan, paths), ne[np.isfinite(ne).all(axis=1)]])
    span_n, span_e = np.ptp(shown, axis=0)
    map_h = map_height_in(span_n, span_e)
    fig, (ax, vx) = plt.subplots(2, 1, figsize=(10, map_h + 4.5), height_ratios=(map_h, 3.0))
    try:
        draw_plan(ax, plan, paths, alpha=0.45, width=3.0)
        east_mid_km = float(shown[:, 1].min() + shown[:, 1].max()) / 2e3
        _draw_track(ax, ne, t_s, states, conts, crashed, east_mid_km)
        _draw_altitude(vx, plan, paths, ivs, conts, truth, t_s, ne, last_ns / 1e9)
        if notes:
            ax.text(0.01, 0.99, "\n".join(notes), transform=ax.transAxes, fontsize=8,
                    va="top", ha="left", color="darkred",
                    bbox={"boxstyle": "round", "facecolor": "lightyellow", "alpha": 0.9})
        final = mission.get("final_state") or (ivs[-1].state if ivs else None)
        fig.suptitle(f"{plan.name} (plan {plan.plan_id}), {run_dir.name}: "
                     f"{final or 'no state reported'}, {legs_flown(paths, judged)}")
        fig.tight_layout()
        fig.savefig(out, dpi=90)
    finally:
        plt.close(fig)


def _draw_track(ax, ne: np.ndarray, t_s: np.ndarray, states: np.ndarray, conts: list[dict],
                crashed: bool, east_mid_km: float) -> None:
    """The flown ground track over the plan, its start and end, the contingencies' events
    (named on the side of the map's middle, east_mid_km, so that the names stay inside)."""
    if not len(ne):
        return
    kind = np.array([s if s in STATE_COLOURS else "other" for s in states], dtype=object)
    others = ", ".join(dict.fromkeys(s for s in states if s not in STATE_COLOURS))
    labels = {"ACTIVE": "flown: ACTIVE", "CONTINGENCY": "flown: CONTINGENCY",
              "other": f"flown: {others}"}
    labelled: set[str] = set()
    for a, b in _runs(kind):
        k = kind[a]
        seg = ne[a:min(b + 1, len(ne))]  # joined to the next run's first sample
        ax.plot(seg[:, 1] / 1e3, seg[:, 0] / 1e3, color=STATE_COLOURS.get(k, OTHER_COLOUR),
                lw=1.4 if k in STATE_COLOURS else 1.0, ls="-" if k in STATE_COLOURS else "--",
                label=None if k in labelled else labels[k], zorder=3)
        labelled.add(k)
    ok = np.flatnonzero(np.isfinite(ne).all(axis=1))
    if len(ok):
        first, last = ne[ok[0]], ne[ok[-1]]
        ax.plot(first[1] / 1e3, first[0] / 1e3, "D", color="tab:green", mec="black", ms=7,
                label=f"start ({t_s[ok[0]]:.0f} s)", zorder=4)
        ax.plot(last[1] / 1e3, last[0] / 1e3, "X" if crashed else "D",
                color="tab:red" if crashed else "white", mec="black", ms=9 if crashed else 7,
                label=f"{'crash' if crashed else 'end'} ({t_s[ok[-1]]:.0f} s)", zorder=4)
    marked: set[str] = set()
    for c in conts:
        for key, marker, colour, name in CONTINGENCY_EVENTS:
            when = c.get(key)
            pos = _position_at(t_s, ne, when) if isinstance(when, (int, float)) else None
            if pos is None:
                continue
            ax.plot(pos[1] / 1e3, pos[0] / 1e3, marker, color=colour, mec="black", ms=8,
                    label=None if name in marked else f"contingency {name}", zorder=5)
            marked.add(name)
            text = f"{c.get('event')} {name}\nat {when:.0f} s"
            if key == "resumed_t_s" and c.get("resumed_leg") is not None:
                text += f", leg {c['resumed_leg']}"
            left = pos[1] / 1e3 > east_mid_km
            ax.annotate(text, (pos[1] / 1e3, pos[0] / 1e3), textcoords="offset points",
                        xytext=(-7 if left else 7, -2), ha="right" if left else "left",
                        va="top", fontsize=7, color=colour, zorder=5)
    # above the map, not over the track
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=4, fontsize=7,
              frameon=False)


def _draw_altitude(vx, plan: Plan, paths: list[LegPath], ivs: list[flown.Interval],
                   conts: list[dict], truth: dict[str, np.ndarray], t_s: np.ndarray,
                   ne: np.ndarray, end_s: float) -> None:
    """Flown and planned altitude against time, the legs' boundaries, the contingencies."""
    alt = truth["alt_ft"]
    plan_alt = planned_altitude(plan, paths, ivs, truth["t_ns"], ne)
    if len(t_s):
        vx.plot(t_s, alt, color="tab:blue", lw=1.0, label="flown (truth)")
        if np.isfinite(plan_alt).any():
            vx.plot(t_s, plan_alt, "--", color="tab:red", lw=1.2, label="planned (leg flown)")
    else:
        vx.text(0.5, 0.5, "no truth samples", transform=vx.transAxes, ha="center",
                va="center", color="darkred")
    by_index = {p.index: p for p in paths}
    previous = None
    for iv in ivs:
        flying = iv.state in FLYING
        key = (iv.leg, iv.type) if flying else iv.state
        if key == previous or iv.state in ("NO_PLAN", "STANDBY"):
            previous = key
            continue
        previous = key
        if flying:
            path = by_index.get(iv.leg)
            planned = path is not None and path.type == iv.type
            text = f"{iv.leg} {iv.type}" + ("" if planned else " (in flight)")
        else:
            text = iv.state
        vx.axvline(iv.t0_ns / 1e9, color="gray", lw=0.5)
        edge = iv.t0_ns / 1e9 > 0.97 * max(end_s, 1.0)  # the name left of the line, inside
        vx.annotate(text, (iv.t0_ns / 1e9, 0.98), xycoords=("data", "axes fraction"),
                    fontsize=7, rotation=90, va="top", ha="right" if edge else "left",
                    textcoords="offset points", xytext=(-1 if edge else 1, 0), color="dimgray",
                    clip_on=True)
    spans = [(c.get("t_s"), c.get("resumed_t_s"), c.get("procedure_t_s"), c.get("event"))
             for c in conts]
    if not spans:  # no event reported, yet a contingency state: shade that
        spans = [(iv.t0_ns / 1e9, iv.t1_ns / 1e9, None, None)
                 for iv in ivs if iv.state == "CONTINGENCY"]
    for k, (t0, t1, tp, event) in enumerate(spans):
        if not isinstance(t0, (int, float)):
            continue
        t1 = t1 if isinstance(t1, (int, float)) else max(end_s, t0)
        vx.axvspan(t0, t1, color="magenta", alpha=0.12, label="contingency" if k == 0 else None)
        if isinstance(tp, (int, float)):
            vx.axvline(tp, color="magenta", lw=0.8, ls=":")
        if event:
            vx.annotate(str(event), (t0, 0.02), xycoords=("data", "axes fraction"),
                        fontsize=7, color="purple", textcoords="offset points", xytext=(2, 0),
                        clip_on=True)
    # the altitudes drawn set the scale (a runway far below a flight that never went there
    # would flatten it); the plan's when nothing is drawn
    values = np.concatenate([alt, plan_alt])
    values = values[np.isfinite(values)]
    if not len(values):
        values = np.array([p.altitude_ft for p in paths] + [plan.cruise_altitude_ft])
    low, top = float(values.min()), float(values.max())
    vx.set_ylim(bottom=low - 300.0, top=top + max(300.0, 0.25 * (top - low)))
    for rw in plan.runways.values():  # shown when within that scale
        vx.axhline(rw.elevation_ft, color="dimgray", lw=0.8, ls="--")
    if len(t_s) or ivs:
        vx.set_xlim(left=0.0, right=max(end_s, 1.0))
    vx.set_xlabel("emulated time (s)")
    vx.set_ylabel("altitude (ft)")
    vx.grid(True, alpha=0.3)
    if vx.get_legend_handles_labels()[0]:
        vx.legend(loc="lower right", fontsize=7, framealpha=0.85)


def _draw_failure(run_dir: Path, plan: Plan, out: Path, exc: Exception) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 3))
    try:
        ax.axis("off")
        ax.text(0.5, 0.5, f"{plan.name} (plan {plan.plan_id}), {run_dir.name}:\nthe track "
                f"could not be drawn: {type(exc).__name__}: {exc}", ha="center", va="center",
                wrap=True, color="darkred")
        fig.savefig(out, dpi=90)
    finally:
        plt.close(fig)


def write_track(run_dir: Path, plan: Plan, judged: dict, out: Path | None = None) -> Path:
    """Draws RUN_DIR/track.png (or `out`) of a run flown with `plan`; `judged` is what
    flown.judge returned (or the summary holding it: its `mission`, `legs`, `contingencies`).
    OSError when the PNG cannot be written; whatever else goes wrong gives a PNG saying so
    (and a TrackWarning), never an exception."""
    run_dir = Path(run_dir)
    out = run_dir / "track.png" if out is None else Path(out)
    try:
        _draw(run_dir, plan, judged or {}, out)
    except OSError:
        raise
    except Exception as exc:  # a post-flight picture must not lose the run's summary
        warnings.warn(f"{out}: the track could not be drawn: {exc!r}", TrackWarning,
                      stacklevel=2)
        _draw_failure(run_dir, plan, out, exc)
    return out
