# SPDX-License-Identifier: Apache-2.0
"""`ima trace replicas`: the redundancy channels' commands against each other and against the
voted value, frame by frame, and when a channel was voted out.

The voted message (default ACT_CMD) is sent by each channel as ACT_CMD_A, _B, _C with
signals ELEV_CMD_A ... . Frames are grouped by the message's cycle (one vote per period, as
the actuators vote); the voted value of a period is the median of three channels, the mean
of two, or the one. A channel's disagreement is its distance to the voted value. `voted_out`
comes from the world's trace in a run directory (what the actuators did); for a log it is
inferred with the actuators' rule: more than the threshold from the voted value for
`persist` periods in a row while three vote (miscompare: with two left, which is wrong
cannot be told), or no frame for two periods (absent), after which the channel is left out
of the vote.
"""

from __future__ import annotations

import json
import statistics
from collections import defaultdict
from pathlib import Path

from ima.errors import ImaError

CHANNELS = ("A", "B", "C")
DEFAULT_THRESHOLD = 0.1
DEFAULT_PERSIST = 3


def _vote(values: list[float]) -> float:
    return statistics.median(values) if len(values) != 2 else (values[0] + values[1]) / 2


def _run_vote_settings(run_dir: Path) -> tuple[list[float] | None, int | None, list[str]]:
    """(thresholds per signal, persist, node names) from the run's launch.json."""
    try:
        info = json.loads((run_dir / "launch.json").read_text())
        cmd = info["commands"]["world"]
    except (OSError, ValueError, KeyError, TypeError):
        return None, None, []
    th = persist = None
    if "--vote-threshold" in cmd:
        th = [float(x) for x in cmd[cmd.index("--vote-threshold") + 1].split(",")]
    if "--vote-persist" in cmd:
        persist = int(cmd[cmd.index("--vote-persist") + 1])
    return th, persist, list(info.get("nodes") or [])


def _world_voted_out(run_dir: Path) -> list[dict] | None:
    path = run_dir / "world.jsonl"
    if not path.is_file():
        return None
    out = []
    with open(path, "rb") as f:
        for line in f:
            if b"voted_out" not in line:
                continue
            try:
                r = json.loads(line)
            except ValueError:
                continue
            if r.get("kind") == "voted_out":
                out.append({"node": r.get("node"), "channel": r.get("channel"),
                            "t_s": round(r["t_ns"] / 1e9, 3), "reason": r.get("reason"),
                            "source": "world"})
    return out


def compute(frames, decoder, message: str = "ACT_CMD", thresholds=None, persist=None,
            nodes: list[str] | None = None, world_voted_out: list[dict] | None = None) -> dict:
    names = {ch: f"{message}_{ch}" for ch in CHANNELS}
    ids = {decoder.id_of(n): ch for ch, n in names.items()}
    ids.pop(None, None)
    if not ids:
        raise ImaError(f"no message {message}_A, _B or _C in {decoder.path}")
    first = names[next(iter(ids.values()))]
    axes = [s[: -2] for s in decoder.signals[first] if s.endswith("_" + ids[decoder.id_of(first)])]
    axes = [a for a in axes if not a.startswith("CMD_CNT")]
    cycle_ns = int((decoder.cycle_ms.get(first) or 50) * 1e6)
    th = thresholds or [DEFAULT_THRESHOLD] * len(axes)
    if len(th) < len(axes):
        th = th + [th[-1]] * (len(axes) - len(th))
    persist = persist or DEFAULT_PERSIST
    periods: dict[int, dict[str, list[float]]] = defaultdict(dict)
    for f in frames:
        ch = ids.get(f.id)
        if ch is None or f.error:
            continue
        sig = decoder.decode(f.id, f.data)
        if sig is None:
            continue
        periods[f.t_ns // cycle_ns][ch] = [float(sig.get(f"{a}_{ch}", 0.0)) for a in axes]
    node_of = {ch: (nodes[i] if nodes and i < len(nodes) else f"channel {ch}")
               for i, ch in enumerate(CHANNELS)}
    present_chs = sorted({ch for p in periods.values() for ch in p})
    series = {"t_s": [], "voted": {a: [] for a in axes},
              "disagreement": {ch: {a: [] for a in axes} for ch in present_chs}}
    per_ch = {ch: {"frames": 0, "max": [0.0] * len(axes), "over": 0} for ch in present_chs}
    inferred, out_set, streak, absent = [], set(), defaultdict(int), defaultdict(int)
    # the vote-outs the actuators decided, in time order: they leave the vote from then on
    decided = sorted((round(v["t_s"] * 1e9), v["channel"]) for v in world_voted_out or [])
    for k in sorted(periods):
        p = periods[k]
        if world_voted_out is not None:
            out_set = {ch for t, ch in decided if t <= k * cycle_ns}
        voting = [ch for ch in p if ch not in out_set]
        if not voting:
            continue
        voted = [_vote([p[ch][i] for ch in voting]) for i in range(len(axes))]
        t_s = round(k * cycle_ns / 1e9, 3)
        series["t_s"].append(t_s)
        for i, a in enumerate(axes):
            series["voted"][a].append(voted[i])
        for ch in present_chs:
            if ch not in p:
                for a in axes:
                    series["disagreement"][ch][a].append(None)
                absent[ch] += 1
                if absent[ch] == 2 and ch not in out_set:
                    out_set.add(ch)
                    inferred.append({"node": node_of[ch], "channel": ch, "t_s": t_s,
                                     "reason": "absent", "source": "inferred"})
                continue
            absent[ch] = 0
            d = [abs(p[ch][i] - voted[i]) for i in range(len(axes))]
            st = per_ch[ch]
            st["frames"] += 1
            st["max"] = [max(x, y) for x, y in zip(st["max"], d, strict=True)]
            over = any(d[i] > th[i] for i in range(len(axes)))
            st["over"] += over
            for i, a in enumerate(axes):
                series["disagreement"][ch][a].append(d[i])
            # with two channels left a miscompare cannot tell which one is wrong
            streak[ch] = streak[ch] + 1 if over and len(voting) >= 3 and ch in voting else 0
            if streak[ch] == persist and ch not in out_set:
                out_set.add(ch)
                inferred.append({"node": node_of[ch], "channel": ch, "t_s": t_s,
                                 "reason": "miscompare", "source": "inferred"})
    return {
        "message": message,
        "axes": axes,
        "period_ms": cycle_ns / 1e6,
        "thresholds": th[: len(axes)],
        "persist": persist,
        "periods": len(series["t_s"]),
        "channels": [{"channel": ch, "node": node_of[ch], "frames": per_ch[ch]["frames"],
                      "max_disagreement": {a: round(per_ch[ch]["max"][i], 5)
                                           for i, a in enumerate(axes)},
                      "periods_over_threshold": per_ch[ch]["over"]} for ch in present_chs],
        "voted_out": world_voted_out if world_voted_out is not None else inferred,
        "voted_out_inferred": inferred,
        "series": series,
    }


# ---- the subcommand ---------------------------------------------------------------------

def add_arguments(p) -> None:
    p.add_argument("input", type=Path, metavar="INPUT",
                   help="a run directory, its can.jsonl, or a log python-can reads")
    p.add_argument("--dbc", type=Path, metavar="FILE", help="default config/can/rpas.dbc")
    p.add_argument("--message", default="ACT_CMD", metavar="NAME",
                   help="the voted message, sent as NAME_A, NAME_B, NAME_C (default ACT_CMD)")
    p.add_argument("--threshold", type=float, metavar="X",
                   help="disagreement threshold (default: the run's, else 0.1)")
    p.add_argument("--persist", type=int, metavar="N",
                   help="periods over the threshold before a vote-out (default: the run's, "
                   "else 3)")
    p.add_argument("--json", action="store_true", help="every figure as one JSON object")
    p.add_argument("--plot", type=Path, metavar="PNG",
                   help="plot each channel's disagreement over time, vote-outs marked")


def run(args) -> int:
    import math

    from ima.trace import source
    from ima.trace.decode import Decoder

    if args.threshold is not None and not (math.isfinite(args.threshold) and
                                           args.threshold > 0):
        raise ImaError("--threshold must be a positive number", exit_code=2)
    if args.persist is not None and args.persist < 1:
        raise ImaError("--persist must be at least 1", exit_code=2)
    trace = source.load(args.input)
    run_dir = args.input if args.input.is_dir() else args.input.parent
    th, persist, nodes = _run_vote_settings(run_dir)
    if args.threshold is not None:
        th = [args.threshold]
    world = _world_voted_out(run_dir) if (run_dir / "can.jsonl").exists() else None
    r = compute(trace.frames, Decoder(args.dbc), args.message, th, args.persist or persist,
                nodes, world)
    r["source"] = trace.source
    if args.plot:
        plot(r, args.plot)
        r["plot"] = str(args.plot)
    if args.json:
        print(json.dumps({k: v for k, v in r.items() if k != "series"}))
    else:
        render(r)
    return 0


def render(r: dict) -> None:
    import sys

    from rich.console import Console
    from rich.table import Table

    out = Console(width=None if sys.stdout.isatty() else 120)
    out.print(f"[bold]{r['source']}[/]: {r['message']}_A/B/C, {r['periods']} periods of "
              f"{r['period_ms']:g} ms, threshold {r['thresholds'][0]:g}, persist {r['persist']}")
    t = Table(show_edge=False, header_style="bold")
    t.add_column("channel")
    t.add_column("frames", justify="right")
    for a in r["axes"]:
        t.add_column(f"max {a}", justify="right")
    t.add_column("over threshold", justify="right")
    for c in r["channels"]:
        t.add_row(f"{c['channel']} ({c['node']})", str(c["frames"]),
                  *(f"{c['max_disagreement'][a]:.4f}" for a in r["axes"]),
                  str(c["periods_over_threshold"]))
    out.print(t)
    if not r["voted_out"]:
        out.print("no channel voted out")
    for v in r["voted_out"]:
        out.print(f"{v['node']} (channel {v['channel']}) voted out at {v['t_s']:.3f} s "
                  f"({v['reason']}, {v['source']})")


def plot(r: dict, png: Path) -> None:
    import matplotlib

    from ima.trace import figure

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    axes = r["axes"]
    fig, axs = plt.subplots(len(axes), 1, figsize=(9, 1.8 * len(axes) + 0.6), sharex=True,
                            squeeze=False)
    t = r["series"]["t_s"]
    for i, a in enumerate(axes):
        ax = axs[i][0]
        for ch, d in r["series"]["disagreement"].items():
            ax.plot(t, [float("nan") if x is None else x for x in d[a]], label=ch, lw=0.9)
        ax.axhline(r["thresholds"][i], color="grey", ls=":", lw=0.8)
        for v in r["voted_out"]:
            ax.axvline(v["t_s"], color="red", lw=0.8)
        ax.set_ylabel(f"|{a} − voted|")
        ax.grid(alpha=0.3)
    axs[0][0].legend(title="channel", loc="upper right", fontsize=8)
    axs[-1][0].set_xlabel("time (s)")
    fig.suptitle(f"{r['source']}: {r['message']} disagreement (red: voted out)", fontsize=9)
    figure.save(fig, png)
