# SPDX-License-Identifier: Apache-2.0
"""The flight at a glance: RUN_DIR/flight.png, altitude, airspeed, heading and bank from the
truth trace, with the autopilot targets and the judged hold segments."""

from __future__ import annotations

from pathlib import Path

from ima.flight.summary import HoldSegment


def plot_flight(truth: list[dict], segments: list[HoldSegment], out: Path, title: str,
                events: list[tuple[float, str]] | None = None) -> Path:
    """`events`: (time s, label) marked on every panel, e.g. a node killed, a replica voted out."""
    # A figure and its canvas directly: a file needs none of pyplot's figure management.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t = [r["t_ns"] / 1e9 for r in truth]
    panels = [("alt_ft", "altitude (ft)", "altitude_ft"),
              ("airspeed_kt", "airspeed (kt)", "airspeed_kt"),
              ("heading_deg", "heading (°)", "heading_deg"), ("roll_deg", "bank (°)", None)]
    fig = Figure(figsize=(10, 9))
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(panels), 1, sharex=True)
    for ax, (key, label, target) in zip(axes, panels, strict=True):
        ax.plot(t, [r[key] for r in truth], lw=0.8, color="tab:blue", label="truth")
        for k, seg in enumerate(segments):
            ax.axvspan(seg.t0_s, seg.t1_s, color="tab:green", alpha=0.08,
                       label="judged hold" if k == 0 else None)
            if target:
                ax.hlines(getattr(seg, target), seg.t0_s, seg.t1_s, colors="tab:red", lw=1.0,
                          linestyles="dashed", label="target" if k == 0 else None)
        for te, _text in events or []:
            ax.axvline(te, color="tab:purple", lw=0.8, ls="--", alpha=0.7)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    # one label per cluster of events (close events would print over each other)
    labels: list[list] = []
    for te, text in sorted(events or []):
        if labels and t and te - labels[-1][0] < 0.02 * (t[-1] - t[0]):
            labels[-1][1] += "; " + text
        else:
            labels.append([te, text])
    for te, text in labels:
        axes[0].annotate(text, (te, 0.98), xycoords=("data", "axes fraction"), fontsize=7,
                         color="tab:purple", rotation=90, va="top", ha="right")
    axes[-1].axhline(30, color="tab:red", lw=0.6, ls=":")
    axes[-1].axhline(-30, color="tab:red", lw=0.6, ls=":")
    axes[0].legend(loc="upper left", fontsize=8)
    axes[-1].set_xlabel("emulated time (s)")
    fig.suptitle(title)
    # fixed margins: tight_layout would draw the whole figure once more to measure it
    fig.subplots_adjust(left=0.085, right=0.985, top=0.94, bottom=0.065, hspace=0.12)
    fig.savefig(out, dpi=90)
    return out
