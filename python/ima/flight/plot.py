# SPDX-License-Identifier: Apache-2.0
"""The flight at a glance: RUN_DIR/flight.png, altitude, airspeed, heading and bank from the
truth trace, with the autopilot targets and the judged hold segments.

Every `ima launch` draws it, so it is drawn with Pillow alone (ima.flight.raster), not
matplotlib: importing matplotlib and drawing this figure with it took about 0.55 s of CPU a
launch, this takes about 0.1 s."""

from __future__ import annotations

from pathlib import Path

from ima.flight.raster import BLUE, GREEN, PURPLE, RED, Canvas, Panel
from ima.flight.summary import HoldSegment

WIDTH, HEIGHT = 900, 810  # pixels: the figure matplotlib drew (10 x 9 in at 90 dpi)
LEFT, RIGHT, TOP, BOTTOM = 76, 886, 49, 757  # the panels' box
GAP = 20  # between two panels
BANK_LIMIT_DEG = 30.0  # dotted on the bank panel
PANELS = (("alt_ft", "altitude (ft)", "altitude_ft"),
          ("airspeed_kt", "airspeed (kt)", "airspeed_kt"),
          ("heading_deg", "heading (°)", "heading_deg"), ("roll_deg", "bank (°)", None))


def plot_flight(truth: list[dict], segments: list[HoldSegment], out: Path, title: str,
                events: list[tuple[float, str]] | None = None) -> Path:
    """`events`: (time s, label) marked on every panel, e.g. a node killed, a replica voted out."""
    events = sorted(events or [])
    t = [r["t_ns"] / 1e9 for r in truth]
    # the flight and every event (one after the truth's end, of a run cut short, widens it)
    xs = t[:1] + t[-1:] + [te for te, _ in events]
    x0, x1 = (min(min(xs), 0.0), max(xs)) if xs else (0.0, 1.0)
    canvas = Canvas(WIDTH, HEIGHT)
    height = (BOTTOM - TOP - GAP * (len(PANELS) - 1)) / len(PANELS)
    panels = []
    for k, (key, label, target) in enumerate(PANELS):
        y = [r[key] for r in truth]
        top = TOP + k * (height + GAP)
        extra = [getattr(s, target) for s in segments] if target else []
        if target is None:
            extra = [-BANK_LIMIT_DEG, BANK_LIMIT_DEG]
        panel = Panel(canvas, (LEFT, top, RIGHT, top + height), (x0, x1),
                      [v for v in y if v is not None] + extra)
        for seg in segments:
            panel.xspan(seg.t0_s, seg.t1_s, GREEN, 0.08)
        panel.grid()
        panel.line(t, y, BLUE)
        for seg in segments:
            if target:
                panel.hline(getattr(seg, target), seg.t0_s, seg.t1_s, RED, dash=(5, 2))
        for te, _text in events:
            panel.vline(te, PURPLE, alpha=0.7, dash=(4, 2))
        if target is None:
            for v in (-BANK_LIMIT_DEG, BANK_LIMIT_DEG):
                panel.hline(v, *panel.xlim, RED, dash=(1, 2))
        panel.frame(ylabel=label, xticks=k == len(PANELS) - 1)
        panels.append(panel)
    # one label per cluster of events (close events would print over each other)
    labels: list[list] = []
    for te, text in events:
        if labels and t and te - labels[-1][0] < 0.02 * (t[-1] - t[0]):
            labels[-1][1] += "; " + text
        else:
            labels.append([te, text])
    for te, text in labels:
        panels[0].vlabel(te, text, PURPLE)
    legend = [("line", BLUE, "truth")]
    if segments:
        legend.append(("patch", GREEN, "judged hold"))
        legend.append(("dash", RED, "target"))
    panels[0].legend(legend)
    panels[-1].xlabel("emulated time (s)")
    canvas.title(title)
    canvas.save(out)
    return out
