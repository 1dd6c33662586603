# SPDX-License-Identifier: Apache-2.0
"""`ima trace plot INPUT --signal MSG.SIGNAL ... -o PNG`: signals over time, one panel per
signal; in a run directory the faults (injected), the vote-outs and the health-monitor
decisions are marked."""

from __future__ import annotations

import json
from pathlib import Path

from ima.errors import ImaError


def _events(run_dir: Path) -> list[tuple[float, str, str]]:
    """(t_s, kind, label): the run's faults, vote-outs and HM decisions."""
    out = []
    try:
        for f in json.loads((run_dir / "launch.json").read_text()).get("faults") or []:
            if f.get("t_s") is not None:
                out.append((float(f["t_s"]), "fault", f"{f.get('id')} {f.get('class')}"))
    except (OSError, ValueError, AttributeError):
        pass
    names = ["world.jsonl", *sorted(p.name for p in run_dir.glob("node*.jsonl"))]
    for name in names:
        try:
            f = open(run_dir / name, "rb")  # noqa: SIM115 - closed below
        except OSError:
            continue
        with f:
            for line in f:
                if b'"voted_out"' not in line and b'"hm"' not in line:
                    continue
                try:
                    r = json.loads(line)
                except ValueError:
                    continue
                t = r.get("t_ns", 0) / 1e9
                if r.get("kind") == "voted_out":
                    out.append((t, "vote", f"{r.get('node')} voted out"))
                elif r.get("kind") == "hm":
                    out.append((t, "hm", f"{r.get('node')} {r.get('partition')} "
                                          f"{r.get('error')}→{r.get('action')}"))
    return sorted(out)


def series(frames, decoder, spec: str) -> tuple[list[float], list[float]]:
    msg, _, sig = spec.partition(".")
    fid = decoder.id_of(msg)
    if fid is None or not sig:
        raise ImaError(f"--signal {spec!r}: expected MESSAGE.SIGNAL of {decoder.path}")
    if sig not in decoder.signals[msg]:
        raise ImaError(f"--signal {spec!r}: {msg} has no signal {sig} (its signals: "
                       f"{', '.join(decoder.signals[msg])})")
    t, v = [], []
    for f in frames:
        if f.id == fid and not f.error:
            d = decoder.decode(f.id, f.data)
            if d is not None and isinstance(d.get(sig), (int, float)):
                t.append(f.t_ns / 1e9)
                v.append(float(d[sig]))
    return t, v


def add_arguments(p) -> None:
    p.add_argument("input", type=Path, metavar="INPUT", help="a run directory or a log")
    p.add_argument("--signal", action="append", required=True, metavar="MSG.SIGNAL",
                   help="a signal to plot, e.g. ACT_CMD_A.ELEV_CMD_A (repeatable)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="PNG")
    p.add_argument("--dbc", type=Path, metavar="FILE", help="default config/can/rpas.dbc")


_COLORS = {"fault": "tab:red", "vote": "tab:purple", "hm": "tab:orange"}


def run(args) -> int:
    import matplotlib

    from ima.trace import figure, source
    from ima.trace.decode import Decoder

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    trace = source.load(args.input)
    dec = Decoder(args.dbc)
    data = [series(trace.frames, dec, s) for s in args.signal]
    run_dir = args.input if args.input.is_dir() else args.input.parent
    events = _events(run_dir) if (run_dir / "can.jsonl").exists() else []
    fig, axs = plt.subplots(len(data), 1, figsize=(10, 2.2 * len(data) + 0.8), sharex=True,
                            squeeze=False)
    for (t, v), spec, row in zip(data, args.signal, axs, strict=True):
        ax = row[0]
        ax.plot(t, v, lw=0.9)
        ax.set_ylabel(spec, fontsize=8)
        ax.grid(alpha=0.3)
        for te, kind, _ in events:
            ax.axvline(te, color=_COLORS[kind], lw=0.7, alpha=0.8)
    for kind, color in _COLORS.items():
        if any(k == kind for _, k, _ in events):
            axs[0][0].plot([], [], color=color, label=kind)
    if events:
        axs[0][0].legend(fontsize=8, loc="upper right")
    axs[-1][0].set_xlabel("time (s)")
    fig.suptitle(trace.source, fontsize=9)
    figure.save(fig, args.output)
    counts = ", ".join(f"{s} ({len(t)} samples)"
                       for s, (t, _) in zip(args.signal, data, strict=True))
    print(f"{args.output}: {counts}" + (f"; {len(events)} events marked" if events else ""))
    return 0
