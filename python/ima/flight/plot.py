# SPDX-License-Identifier: Apache-2.0
"""The flight at a glance: RUN_DIR/flight.png, altitude, airspeed, heading and bank from the
truth trace, with the autopilot targets and the judged hold segments."""

from __future__ import annotations

from pathlib import Path

from ima.flight.summary import HoldSegment


def plot_flight(truth: list[dict], segments: list[HoldSegment], out: Path, title: str) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = [r["t_ns"] / 1e9 for r in truth]
    panels = [("alt_ft", "altitude (ft)", "altitude_ft"), ("airspeed_kt", "airspeed (kt)", "airspeed_kt"),
              ("heading_deg", "heading (°)", "heading_deg"), ("roll_deg", "bank (°)", None)]
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 9), sharex=True)
    for ax, (key, label, target) in zip(axes, panels):
        ax.plot(t, [r[key] for r in truth], lw=0.8, color="tab:blue", label="truth")
        for k, seg in enumerate(segments):
            ax.axvspan(seg.t0_s, seg.t1_s, color="tab:green", alpha=0.08,
                       label="judged hold" if k == 0 else None)
            if target:
                ax.hlines(getattr(seg, target), seg.t0_s, seg.t1_s, colors="tab:red", lw=1.0,
                          linestyles="dashed", label="target" if k == 0 else None)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].axhline(30, color="tab:red", lw=0.6, ls=":")
    axes[-1].axhline(-30, color="tab:red", lw=0.6, ls=":")
    axes[0].legend(loc="upper left", fontsize=8)
    axes[-1].set_xlabel("emulated time (s)")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out
