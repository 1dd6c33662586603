# SPDX-License-Identifier: Apache-2.0
"""`ima trace stats`: the bus load per window and, per identifier, the count, the periods
against the DBC's cycle times, the gaps and the deadline misses; error frames, bus-off.

- Bus load: the bit times of every frame (bits.frame_bits: exact, stuff bits included) over
  the bit rate times the window; `*_worst_case` uses bits.worst_case_bits instead (what a
  schedulability analysis budgets; the emulated bus times frames with it).
- Periods: the intervals between consecutive frames of an identifier (p50, p99, max; the
  percentiles are the nearest-rank ones, numpy's "inverted_cdf").
  The nominal period is the DBC's cycle time (GenMsgCycleTime), else the median interval.
  `jitter_ms`: p99 minus p1 of the intervals. A `deadline_miss` is an interval longer than
  the nominal period by more than `late_tolerance` (10 %); a `gap` one of at least 1.5
  periods (a frame missing).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ima.trace import bits
from ima.trace.source import Trace

if TYPE_CHECKING:  # numpy is imported when statistics are computed, not with the CLI
    from ima.trace.columns import Columns

DEFAULT_WINDOW_S = 1.0
DEFAULT_BITRATE = 1_000_000
LATE_TOLERANCE = 0.10
GAP_FACTOR = 1.5


def _r(x: float | None, nd: int = 3) -> float | None:
    return None if x is None else round(x, nd)


def load_dbc(path: Path | None):
    """The DBC (cantools), default config/can/rpas.dbc; None if it cannot be read."""
    import cantools

    from ima import paths
    from ima.errors import ImaError

    path = path or paths.repo_root() / "config" / "can" / "rpas.dbc"
    try:
        return cantools.database.load_file(str(path), strict=False)
    except (OSError, ValueError, cantools.database.UnsupportedDatabaseFormatError) as e:
        raise ImaError(f"{path}: cannot read the DBC: {e}") from e


def _message(dbc, can_id: int, extended: bool):
    """The DBC's message of an identifier (cantools keeps 29-bit ones without the flag)."""
    if dbc is None:
        return None
    try:
        msg = dbc.get_message_by_frame_id(can_id)
    except KeyError:
        return None
    return msg if bool(msg.is_extended_frame) == extended else None


def compute(trace: Trace | Columns, dbc=None, window_s: float = DEFAULT_WINDOW_S,
            bitrate: int | None = None) -> dict:
    """The statistics of a trace (see the module's doc for each figure)."""
    import numpy as np

    from ima.trace import columns

    c = trace if isinstance(trace, columns.Columns) else columns.of_trace(trace)
    rate = bitrate or c.bitrate or DEFAULT_BITRATE
    win_ns = max(1, round(window_s * 1e9))
    ok = ~c.error
    n_errors = int(np.count_nonzero(c.error))
    t, ids_, ext, rtr, dlen = c.t_ns[ok], c.id[ok], c.ext[ok], c.rtr[ok], c.dlen[ok]
    n = len(t)
    end_ns = max(c.duration_ns or 0, int(t[-1]) if n else 0)
    n_win = max(1, -(-end_ns // win_ns))
    exact_bits = bits.frame_bits_columns(ids_, ext, rtr, dlen, c.data[ok])
    g = np.where(ext, 54, 34)
    worst_bits = g + 8 * dlen + 13 + (g + 8 * dlen - 1) // 4  # bits.worst_case_bits
    w = np.minimum(t // win_ns, n_win - 1)
    exact = np.bincount(w, weights=exact_bits, minlength=n_win)
    worst = np.bincount(w, weights=worst_bits, minlength=n_win)
    count = np.bincount(w, minlength=n_win)
    capacity = rate * window_s
    windows = [{"t_s": _r(i * window_s), "frames": int(count[i]),
                "load": _r(exact[i] / capacity, 4), "load_worst_case": _r(worst[i] / capacity, 4)}
               for i in range(n_win)]
    total_s = n_win * window_s
    # per identifier: its frames' times, in order (a stable sort keeps equal times' order)
    key = ids_ * 2 + ext
    order = np.argsort(key, kind="stable")
    keys_sorted = key[order]
    starts = np.flatnonzero(np.r_[True, keys_sorted[1:] != keys_sorted[:-1]])
    bounds = np.r_[starts, n]
    ids = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        k = int(keys_sorted[a])
        can_id, is_ext = k >> 1, bool(k & 1)
        ids.append(_id_stats(can_id, is_ext, np.sort(t[order[a:b]]),
                             _message(dbc, can_id, is_ext)))
    return {
        "source": c.source,
        "frames": n,
        "error_frames": n_errors,
        "duration_s": _r(end_ns / 1e9),
        "bitrate": rate,
        "bitrate_known": bool(bitrate or c.bitrate),
        "window_s": window_s,
        "bus_load": _r(float(exact.sum()) / (rate * total_s), 4),
        "bus_load_worst_case": _r(float(worst.sum()) / (rate * total_s), 4),
        "bus_load_max": max((w["load"] for w in windows), default=0.0),
        "windows": windows,
        "ids": ids,
        "deadline_misses": sum(i["deadline_misses"] for i in ids),
        "gaps": sum(i["gaps"] for i in ids),
        "bus_off": c.bus_off,
    }


def _id_stats(can_id: int, ext: bool, times, msg) -> dict:
    """times: the identifier's frame times (ns, sorted numpy array)."""
    import numpy as np

    periods = np.diff(times) / 1e6
    cycle = msg.cycle_time if msg is not None and msg.cycle_time else None
    p = np.percentile(periods, [1, 50, 99], method="inverted_cdf") if len(periods) else None
    nominal = cycle or (float(p[1]) if p is not None else None)
    late = gaps = 0
    if nominal and len(periods):
        late = int(np.count_nonzero(periods > nominal * (1 + LATE_TOLERANCE)))
        gaps = int(np.count_nonzero(periods >= nominal * GAP_FACTOR))
    return {
        "id": can_id,
        "hex": f"0x{can_id:08X}" if ext else f"0x{can_id:03X}",
        "extended": ext,
        "name": msg.name if msg is not None else None,
        "count": len(times),
        "cycle_ms": cycle,
        "period_ms_p50": _r(float(p[1])) if p is not None else None,
        "period_ms_p99": _r(float(p[2])) if p is not None else None,
        "period_ms_max": _r(float(periods.max())) if len(periods) else None,
        "jitter_ms": _r(float(p[2] - p[0])) if p is not None else None,
        "deadline_misses": late,
        "gaps": gaps,
    }


# ---- the subcommand ---------------------------------------------------------------------

def add_arguments(p) -> None:
    p.add_argument("input", type=Path, metavar="INPUT",
                   help="a run directory, its can.jsonl, or a log python-can reads (.asc, "
                   ".blf, .log, .trc, .csv)")
    p.add_argument("--dbc", type=Path, metavar="FILE",
                   help="the DBC naming the identifiers and giving their cycle times (default "
                   "config/can/rpas.dbc)")
    p.add_argument("--window", type=float, default=DEFAULT_WINDOW_S, metavar="SECONDS",
                   help=f"the bus load's window (default {DEFAULT_WINDOW_S:g} s)")
    p.add_argument("--bitrate", type=int, metavar="BIT/S",
                   help="the bus's bit rate (default: the run's; 1 Mbit/s for a log)")
    p.add_argument("--json", action="store_true", help="every figure as one JSON object")
    p.add_argument("--plot", type=Path, metavar="PNG", help="plot the bus load per window")


def run(args) -> int:
    import json
    import math

    from ima.errors import ImaError
    from ima.trace import columns

    if not (math.isfinite(args.window) and args.window > 0):
        raise ImaError("--window must be a positive number of seconds", exit_code=2)
    if args.bitrate is not None and args.bitrate <= 0:
        raise ImaError("--bitrate must be positive", exit_code=2)
    trace = columns.load(args.input)
    result = compute(trace, load_dbc(args.dbc), args.window, args.bitrate)
    if args.plot:
        plot(result, args.plot)
        result["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(result))
    else:
        render(result)
    return 0


def render(r: dict) -> None:
    import sys

    from rich.console import Console
    from rich.table import Table

    out = Console(width=None if sys.stdout.isatty() else 120)
    assumed = "" if r["bitrate_known"] else " (assumed: pass --bitrate)"
    out.print(f"[bold]{r['source']}[/]: {r['frames']} frames, {r['error_frames']} error frames "
              f"in {r['duration_s']} s at {r['bitrate']:,} bit/s{assumed}")
    out.print(f"bus load {100 * r['bus_load']:.2f} % (worst-case frame lengths "
              f"{100 * r['bus_load_worst_case']:.2f} %), busiest {r['window_s']:g} s window "
              f"{100 * r['bus_load_max']:.2f} %; {r['deadline_misses']} deadline misses, "
              f"{r['gaps']} gaps")
    for ep in r["bus_off"]:
        until = "the end" if ep["until_s"] is None else f"{ep['until_s']:.3f} s"
        out.print(f"bus-off: {ep['client']} from {ep['t_s']:.3f} s to {until}")
    t = Table(show_edge=False, header_style="bold")
    for col in ("id", "name", "count", "cycle ms", "p50 ms", "p99 ms", "max ms", "jitter ms",
                "late", "gaps"):
        t.add_column(col, justify="left" if col in ("id", "name") else "right")

    def f(x):
        return "-" if x is None else f"{x:g}"
    for i in r["ids"]:
        t.add_row(i["hex"], i["name"] or "?", str(i["count"]), f(i["cycle_ms"]),
                  f(i["period_ms_p50"]), f(i["period_ms_p99"]), f(i["period_ms_max"]),
                  f(i["jitter_ms"]), str(i["deadline_misses"]), str(i["gaps"]))
    out.print(t)


def plot(r: dict, png: Path) -> None:
    """The bus load per window, exact and worst-case."""
    import matplotlib

    from ima.trace import figure

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = [w["t_s"] for w in r["windows"]]
    fig, ax = plt.subplots(figsize=(9, 3.5))
    ax.step(t, [100 * w["load"] for w in r["windows"]], where="post", label="exact (stuffed)")
    ax.step(t, [100 * w["load_worst_case"] for w in r["windows"]], where="post",
            linestyle="--", label="worst-case frame lengths")
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"bus load per {r['window_s']:g} s (%)")
    ax.set_title(f"{r['source']}: {r['bitrate']:,} bit/s")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend()
    figure.save(fig, png)
