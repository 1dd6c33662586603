# SPDX-License-Identifier: Apache-2.0
"""A recording's main channels in one PNG: altitude and airspeed, attitude, the flight-control
mode, and the health-monitor decisions as marks."""

from __future__ import annotations

from pathlib import Path


def plot(rec, out: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ima.fdr.records import MODES

    nav = [(f["t_ns"] / 1e9, f["nav"]) for f in rec.frames if f["nav"]]
    st = [(f["t_ns"] / 1e9, f["status"]) for f in rec.frames if f["status"]]
    fig, ax = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    t = [x for x, _ in nav]
    ax[0].plot(t, [n["alt_ft"] for _, n in nav], label="altitude (ft)")
    ax[0].legend(loc="upper left")
    a2 = ax[0].twinx()
    a2.plot(t, [n["ias_kt"] for _, n in nav], color="tab:orange", label="IAS (kt)")
    a2.legend(loc="upper right")
    ax[1].plot(t, [n["roll_deg"] for _, n in nav], label="roll (deg)")
    ax[1].plot(t, [n["pitch_deg"] for _, n in nav], label="pitch (deg)")
    ax[1].legend(loc="upper left")
    ax[2].step([x for x, _ in st], [s["mode"] for _, s in st], where="post", label="mode")
    ax[2].set_yticks(range(len(MODES)), MODES)
    for k, g in enumerate(rec.gaps):
        for a in ax[:3]:
            a.axvspan(g["t_s"] - g["missing"] * 0.05, g["t_s"], color="red", alpha=0.2,
                      label="gap" if k == 0 and a is ax[2] else None)
    ax[2].legend(loc="upper left")
    hm = rec.hm
    ax[3].scatter([h["hm_t_ns"] / 1e9 for h in hm], [h["partition"] for h in hm], marker="x")
    ax[3].set_ylabel("HM decisions")
    ax[3].set_xlabel("time (s)")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
