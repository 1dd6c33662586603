# SPDX-License-Identifier: Apache-2.0
"""Runs the ima-ske separation kernel emulator on one module and shows its schedule statistics."""

from __future__ import annotations

import functools
import json
import os
import signal
import subprocess
import tempfile
import threading
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import IO, Any

from ima import paths
from ima.errors import ImaError

# ima-ske exit codes.
EXIT_OK = 0
EXIT_RUNTIME_FAILURE = 1
EXIT_CONFIG_ERROR = 2  # ima-ske has already printed "FILE:LINE: error: ELEMENT: ..." on stderr

_FORWARDED_SIGNALS = (signal.SIGINT, signal.SIGTERM)
# Ctrl-C is forwarded as it comes; from this many on, the emulator is killed outright.
_KILL_AFTER_SIGNALS = 3


class SkeInterrupted(KeyboardInterrupt):
    """ima-ske was stopped by SIGINT/SIGTERM sent to us; it has exited.

    It is a KeyboardInterrupt so callers that do not care just stop, while a caller that does
    can still show the statistics of the part that ran before re-raising.
    """

    def __init__(self, signum: int, returncode: int, stats: dict | None) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum
        self.returncode = returncode
        self.stats = stats


def build_command(
    binary: Path,
    module_xml: Path,
    *,
    stats_file: Path,
    frames: int | None = None,
    realtime: bool = False,
    trace: str | os.PathLike | None = None,
    node: str | None = None,
    extra_args: Iterable[str] = (),
) -> list[str]:
    """The ima-ske command line for one run (options first, the module last)."""
    cmd = [str(binary), "--stats", str(stats_file)]
    if frames is not None:
        cmd += ["--frames", str(frames)]
    if realtime:
        cmd.append("--realtime")
    if trace is not None:
        cmd += ["--trace", str(trace)]
    if node is not None:
        cmd += ["--node", node]
    cmd += list(extra_args)
    cmd += ["--", str(module_xml)]  # a module path that starts with '-' is no option
    return cmd


def _check_module_file(module_xml: str | os.PathLike) -> Path:
    path = Path(module_xml)
    if not path.is_file():
        raise ImaError(f"{path}: no such module configuration file", exit_code=EXIT_CONFIG_ERROR)
    return path


_PR_SET_PDEATHSIG = 1


@functools.cache
def _prctl():
    """libc's prctl, or None; looked up in the parent, before any fork."""
    import ctypes

    try:
        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None


def _stop_with_parent() -> None:
    """Runs in the child before exec: if ima dies (even by SIGKILL), the emulator gets SIGTERM.

    Needed because the child is in its own process group, out of reach of the terminal's
    signals; without it a killed ima would leave ima-ske and its partitions running.
    """
    prctl = _prctl()
    if prctl is not None:
        prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


def _wait_forwarding_signals(
    cmd: Sequence[str], stdout: int | IO[Any] | None
) -> tuple[int, int | None]:
    """Runs `cmd` until it exits; SIGINT/SIGTERM received meanwhile are passed on to it.

    Returns (returncode, first signal received or None). The child gets its own process group
    so a Ctrl-C at the terminal reaches it once, through us, and it can stop cleanly (write its
    statistics and trace, stop its partitions).
    """
    received: list[int] = []
    pending: list[int] = []
    proc: subprocess.Popen | None = None

    def forward(signum: int, _frame: object) -> None:
        received.append(signum)
        if proc is None:
            pending.append(signum)  # not started yet: sent right after start
            return
        try:
            if len(received) >= _KILL_AFTER_SIGNALS:
                proc.kill()
            else:
                proc.send_signal(signum)
        except ProcessLookupError:
            pass

    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = {}
    if in_main_thread:
        # Installed before the child starts, so no signal can slip between start and wait.
        previous = {s: signal.signal(s, forward) for s in _FORWARDED_SIGNALS}
    _prctl()
    try:
        try:
            proc = subprocess.Popen(
                cmd, stdout=stdout, process_group=0, preexec_fn=_stop_with_parent
            )
        except OSError as exc:
            raise ImaError(f"cannot start {cmd[0]}: {exc.strerror}") from exc
        if pending:
            proc.send_signal(pending[0])
        returncode = proc.wait()
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    return returncode, (received[0] if received else None)


def _read_stats(path: Path) -> dict | None:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    if not text.strip():
        return None
    try:
        stats = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ImaError(f"{path}: ima-ske wrote unreadable statistics: {exc}") from exc
    if not isinstance(stats, dict):
        raise ImaError(f"{path}: ima-ske statistics are not a JSON object")
    return stats


def run_module(
    module_xml: str | os.PathLike,
    frames: int | None = None,
    realtime: bool = False,
    trace: str | os.PathLike | None = None,
    stats_path: str | os.PathLike | None = None,
    node: str | None = None,
    extra_args: Iterable[str] = (),
    quiet: bool = False,
) -> tuple[int, dict | None]:
    """Runs ima-ske on one module; returns (ima-ske exit code, statistics or None).

    `stats_path` keeps the statistics JSON in that file (else a temporary file is used).
    `quiet` discards ima-ske's standard output; its standard error (errors) still shows.
    A negative exit code means ima-ske was killed by that signal.
    Raises SkeInterrupted (a KeyboardInterrupt) once ima-ske has stopped after Ctrl-C/SIGTERM.
    """
    binary = paths.ske_binary()
    module = _check_module_file(module_xml)
    stdout = subprocess.DEVNULL if quiet else None
    with tempfile.TemporaryDirectory(prefix="ima-ske-") as tmp:
        stats_file = Path(stats_path) if stats_path is not None else Path(tmp) / "stats.json"
        cmd = build_command(
            binary,
            module,
            stats_file=stats_file,
            frames=frames,
            realtime=realtime,
            trace=trace,
            node=node,
            extra_args=extra_args,
        )
        returncode, signum = _wait_forwarding_signals(cmd, stdout)
        stats = _read_stats(stats_file)
    if signum is not None:
        raise SkeInterrupted(signum, returncode, stats)
    return returncode, stats


def check_module(module_xml: str | os.PathLike, timeout: float = 60.0) -> tuple[int, str]:
    """Validates a module with `ima-ske --check`; returns (exit code, its standard error text)."""
    binary = paths.ske_binary()
    cmd = [str(binary), "--check", "--", str(module_xml)]
    try:
        done = subprocess.run(
            cmd,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired as exc:
        raise ImaError(f"ima-ske --check {module_xml}: no answer after {timeout:g} s") from exc
    return done.returncode, done.stderr


# --- schedule summary -------------------------------------------------------------------------

_NONE = "—"
_STATE_STYLE = {
    "running": "green",
    "idle": "yellow",
    "stopped": "yellow",
    "exited": "yellow",
    "crashed": "red",
}


def _num(value: Any, fmt: str) -> str:
    if value is None:
        return _NONE
    try:
        return format(value, fmt)
    except (TypeError, ValueError):
        return str(value)


def _ms(ns: Any) -> str:
    return _NONE if ns is None else _num(ns / 1e6, ".3f")


def _state(part: Mapping[str, Any]) -> tuple[str, str]:
    """The state text of a partition row and its style."""
    state = str(part.get("state") or _NONE)
    status = part.get("exit_signal") or part.get("exit_status")
    if status is not None:
        state = f"{state} ({'SIG' + status if part.get('exit_signal') else status})"
    return state, _STATE_STYLE.get(part.get("state") or "", "")


def speed_up(stats: Mapping[str, Any]) -> float | None:
    """Emulated seconds per wall-clock second, or None if not known."""
    emulated_ns, wall_s = stats.get("emulated_ns"), stats.get("wall_s")
    if emulated_ns is None or not wall_s:
        return None
    return emulated_ns / 1e9 / wall_s


def _speed(value: float | None) -> str:
    if value is None:
        return _NONE
    return f"×{value:.0f}" if value >= 10 else f"×{value:.2f}"


def run_lines(stats: Mapping[str, Any]) -> list[str]:
    """Lines describing the whole run: mode, length and speed; window switch; jitter."""
    emulated_ns = stats.get("emulated_ns")
    emulated = _NONE if emulated_ns is None else _num(emulated_ns / 1e9, ".3f")
    first = (
        f"Run: {stats.get('mode') or _NONE}, {_num(stats.get('frames'), 'd')} frames, "
        f"{emulated} s emulated, {_num(stats.get('wall_s'), '.3f')} s wall, "
        f"speed-up {_speed(speed_up(stats))}"
    )
    if stats.get("exit_reason") not in (None, "frames"):
        first += f", ended by {stats['exit_reason']}"
    lines = [first]
    hm_events = stats.get("hm_events")
    if hm_events:
        restarts = sum(p.get("restarts") or 0 for p in stats.get("partitions") or [])
        lines.append(f"Health monitor: {hm_events} decisions, {restarts} partition restarts "
                     "(the trace's hm events say which)")
    switch = stats.get("window_switch_us")
    if switch:
        lines.append(
            f"Window switch: median {_num(switch.get('median'), '.1f')} µs, "
            f"p99 {_num(switch.get('p99'), '.1f')} µs"
        )
    jitter = stats.get("jitter_us")
    if stats.get("mode") == "realtime" or jitter:
        jitter = jitter or {}
        lines.append(
            f"Jitter: median {_num(jitter.get('median'), '.1f')} µs, "
            f"p99 {_num(jitter.get('p99'), '.1f')} µs, max {_num(jitter.get('max'), '.1f')} µs"
        )
    return lines


_TIMELINE_STYLES = ("cyan", "magenta", "green", "yellow", "blue", "red", "bright_cyan",
                    "bright_magenta")


def partition_letters(names: list[str]) -> dict[str, str]:
    """One distinct character per partition: its initial, else its next unused letter, else a digit."""
    used: set[str] = set()
    letters: dict[str, str] = {}
    for name in names:
        if name in letters:
            continue
        candidates = [c.upper() for c in name if c.isalnum()] + list("123456789")
        letter = next((c for c in candidates if c not in used), "?")
        used.add(letter)
        letters[name] = letter
    return letters


def timeline(stats: Mapping[str, Any], width: int = 60) -> list[tuple[str, str]]:
    """The major frame as one row of cells: [(character, partition name or ""), ...].

    Each of `width` cells covers major_frame/width; a cell shows the partition whose window
    covers most of it (its initial), "·" when no window does.
    """
    maf = stats.get("major_frame_ns") or 0
    windows = stats.get("windows") or []
    if not maf or not windows:
        return []
    letters = partition_letters([p.get("name") or "?" for p in stats.get("partitions") or []]
                                + [w["partition"] for w in windows])
    cells = []
    for i in range(width):
        lo, hi = maf * i / width, maf * (i + 1) / width
        best, best_cover = "", 0.0
        for w in windows:
            start, end = w["offset_ns"], w["offset_ns"] + w["duration_ns"]
            cover = min(hi, end) - max(lo, start)
            if cover > best_cover:
                best, best_cover = w["partition"], cover
        cells.append((letters.get(best, "?") if best else "·", best))
    return cells


def _timeline_text(stats: Mapping[str, Any], width: int = 52):
    from rich.text import Text

    cells = timeline(stats, width)
    if not cells:
        return None
    names = [p.get("name") for p in stats.get("partitions") or []]
    style = {n: _TIMELINE_STYLES[i % len(_TIMELINE_STYLES)] for i, n in enumerate(names)}
    text = Text("Major frame  |")
    for ch, name in cells:
        text.append(ch, style=f"bold {style.get(name, '')}" if name else "dim")
    maf_ms = stats["major_frame_ns"] / 1e6
    text.append(f"| {maf_ms:g} ms\n")
    text.append("             ")
    letters = partition_letters([n or "?" for n in names])
    for i, n in enumerate(names):
        text.append(("  " if i else " ") + f"{letters[n or '?']}={n}", style=style.get(n, ""))
    return text


def format_summary(stats: Mapping[str, Any]):
    """The schedule summary of one ima-ske run as a rich renderable."""
    from rich import box
    from rich.console import Group
    from rich.table import Table
    from rich.text import Text

    maf_ns = stats.get("major_frame_ns")
    title = f"Module {stats.get('module') or _NONE}"
    if stats.get("node"):
        title += f" on {stats['node']}"
    if maf_ns:
        title += f" — major frame {maf_ns / 1e6:g} ms"

    parts = Table(
        title=Text(title),
        title_justify="left",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
    )
    # Two-line headings keep the table within 80 columns; numbers never wrap, names may.
    for name in (
        "ID",
        "Partition",
        "Windows\n/frame",
        "Time\nms/frame",
        "Share\n%",
        "Windows\nrun",
        "CPU\nms",
        "Over-\nruns",
        "State",
    ):
        if name in ("Partition", "State"):
            parts.add_column(name, min_width=9)
        else:
            parts.add_column(name, justify="right", no_wrap=True)
    for p in stats.get("partitions") or []:
        window_ns = p.get("window_ns_per_frame")
        share = window_ns / maf_ns * 100 if window_ns is not None and maf_ns else None
        overruns = p.get("overruns")
        # Text, not markup: names come from the configuration and may hold brackets.
        parts.add_row(
            Text(_num(p.get("id"), "d")),
            Text(str(p.get("name") or _NONE)),
            Text(_num(p.get("windows_per_frame"), "d")),
            Text(_ms(window_ns)),
            Text(_num(share, ".1f")),
            Text(_num(p.get("windows"), "d")),
            Text(_ms(p.get("cpu_ns"))),
            Text(_num(overruns, "d"), style="red" if overruns else ""),
            Text(*_state(p)),
        )

    items: list = [parts]
    bar = _timeline_text(stats)
    if bar is not None:
        items.append(bar)
    items += [Text(line) for line in run_lines(stats)]
    channels = stats.get("channels") or []
    if channels:
        table = Table(
            title="Channels",
            title_justify="left",
            box=box.SIMPLE_HEAD,
            pad_edge=False,
            collapse_padding=True,
        )
        for name in ("Channel", "Kind", "Messages", "Overflows"):
            table.add_column(name, justify="left" if name in ("Channel", "Kind") else "right")
        for c in channels:
            overflows = c.get("overflows")
            table.add_row(
                Text(str(c.get("name") or _NONE)),
                Text(str(c.get("kind") or _NONE)),
                Text(_num(c.get("messages"), "d")),
                Text(_num(overflows, "d"), style="red" if overflows else ""),
            )
        items.append(table)
    return Group(*items)


def print_summary(stats: Mapping[str, Any], console=None) -> None:
    """Prints the schedule summary on `console` (a rich Console; standard output if None)."""
    if console is None:
        from rich.console import Console

        console = Console()
    console.print(format_summary(stats))
