# SPDX-License-Identifier: Apache-2.0
"""A mission plan in one PNG: the map (east and north in km of the local frame: each leg
labelled with its index and type, entries dashed, procedures in their own colour, waypoints
and runways) and the vertical profile (planned altitude against the distance along the
mission). `draw_plan` draws the map's planned path; ima.mission.track draws a flight over it."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ima.mission.geometry import Frame, LegPath, Profile, unit
from ima.mission.plan import Plan

_KIND_COLOURS = {"point": "black", "line": "tab:blue", "arc": "tab:purple",
                 "racetrack": "tab:orange", "scan": "tab:green", "dubins": "tab:cyan",
                 "final": "tab:brown"}
_PROCEDURE_COLOUR = "tab:red"


def _runway(frame: Frame, rw) -> tuple[np.ndarray, np.ndarray]:
    """The runway's outline and its centre line (threshold to end)."""
    thr = frame.to_local(rw.lat_deg, rw.lon_deg)
    u, side = unit(rw.heading_deg), unit(rw.heading_deg + 90.0) * rw.width_m / 2.0
    end = thr + rw.length_m * u
    return np.array([thr - side, end - side, end + side, thr + side]), np.array([thr, end])


def extent_points(plan: Plan, paths: list[LegPath]) -> np.ndarray:
    """Every point the map shows (north, east in metres): the origin, the legs, the waypoints."""
    frame = Frame(plan.origin_lat_deg, plan.origin_lon_deg)
    return np.concatenate([np.zeros((1, 2))] + [p.points for p in paths] +
                          [frame.to_local(w.lat_deg, w.lon_deg)[None] for w in
                           plan.waypoints.values()])


def map_height_in(span_n_m: float, span_e_m: float) -> float:
    """The height (inches) of a map 9 inches wide showing that much north and east."""
    return min(max(9.0 * (span_n_m + 1000.0) / (span_e_m + 1000.0), 4.0), 11.0)


def _halfway(points: np.ndarray) -> np.ndarray:
    """The point halfway along a polyline."""
    if len(points) < 2:
        return points[0]
    run = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    half = run[-1] / 2.0
    return np.array([np.interp(half, run, points[:, 0]), np.interp(half, run, points[:, 1])])


def draw_plan(ax, plan: Plan, paths: list[LegPath], alpha: float = 1.0,
              width: float = 1.5) -> None:
    """The planned path on a map (east and north in km): every leg labelled with its index and
    type halfway along it, entries dotted, procedures dashed in their own colour; waypoints and
    runways. `alpha` and `width` (points) for the legs' lines."""
    frame = Frame(plan.origin_lat_deg, plan.origin_lon_deg)
    for p in paths:
        colour = _PROCEDURE_COLOUR if p.procedure else _KIND_COLOURS[p.kind]
        style = "--" if p.procedure else "-"
        if len(p.entry):
            ax.plot(p.entry[:, 1] / 1e3, p.entry[:, 0] / 1e3, ":", color=colour, lw=1,
                    alpha=alpha)
        if len(p.points) == 0:
            continue
        ax.plot(p.points[:, 1] / 1e3, p.points[:, 0] / 1e3, style, color=colour, lw=width,
                alpha=alpha)
        mid = _halfway(p.points)
        name = p.label + (f" ({p.procedure})" if p.procedure else "")
        ax.annotate(name, (mid[1] / 1e3, mid[0] / 1e3), textcoords="offset points",
                    xytext=(4, 4), fontsize=8, color=colour)
    for w in plan.waypoints.values():
        n, e = frame.to_local(w.lat_deg, w.lon_deg)
        ax.plot(e / 1e3, n / 1e3, "^", color="black", ms=5)
        ax.annotate(w.name, (e / 1e3, n / 1e3), textcoords="offset points", xytext=(4, -10),
                    fontsize=7)
    for rw in plan.runways.values():
        box, line = _runway(frame, rw)
        ax.fill(box[:, 1] / 1e3, box[:, 0] / 1e3, color="dimgray")
        # at a map's scale the outline is a hair: the centre line drawn thick shows where it is
        ax.plot(line[:, 1] / 1e3, line[:, 0] / 1e3, color="dimgray", lw=4, solid_capstyle="butt")
        centre = line.mean(axis=0)
        ax.annotate(f"{rw.name} ({rw.heading_deg:03.0f}°, {rw.elevation_ft:g} ft)",
                    (centre[1] / 1e3, centre[0] / 1e3), textcoords="offset points",
                    xytext=(0, -14), fontsize=8, ha="center")
    ax.plot(0.0, 0.0, "+", color="gray", ms=10)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east (km)")
    ax.set_ylabel("north (km)")
    ax.grid(True, alpha=0.3)


def plot(plan: Plan, paths: list[LegPath], profile: Profile, out: Path) -> None:
    """The plan's PNG (`ima mission show`): its map over its vertical profile."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    span_n, span_e = np.ptp(extent_points(plan, paths), axis=0)
    map_h = map_height_in(span_n, span_e)
    fig, (ax, vx) = plt.subplots(2, 1, figsize=(10, map_h + 4.0), height_ratios=(map_h, 3.0))
    draw_plan(ax, plan, paths)
    ax.set_title(f"{plan.name} (plan {plan.plan_id}): {plan.path}")

    km = profile.distance_m / 1e3
    vx.plot(km, profile.altitude_ft, color="tab:blue")
    top = float(np.max(profile.altitude_ft)) if len(km) else plan.cruise_altitude_ft
    for index, start in profile.leg_start_m.items():
        if paths[index].total_m == 0.0:  # an IF: where the next leg starts
            continue
        vx.axvline(start / 1e3, color="gray", lw=0.5, ls=":")
        vx.annotate(f"{index} {paths[index].type}", (start / 1e3, top), fontsize=7,
                    rotation=90, va="top", textcoords="offset points", xytext=(2, 0))
    for rw in plan.runways.values():
        vx.axhline(rw.elevation_ft, color="dimgray", lw=0.8, ls="--")
    vx.set_xlabel("distance along the mission (km)")
    vx.set_ylabel("planned altitude (ft)")
    low = float(np.min(profile.altitude_ft)) if len(km) else top
    vx.set_ylim(bottom=low - 300.0, top=top + max(300.0, 0.25 * (top - low)))
    vx.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
