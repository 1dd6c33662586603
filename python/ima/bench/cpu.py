# SPDX-License-Identifier: Apache-2.0
"""Where a flight's CPU time goes: the CPU time (user + system, from the kernel's accounting in
/proc) of every process of a run, summed by kind (the bus, the world, the SKEs, the DDS
agents, each partition, `ima launch` itself, the recorder), and its peak resident memory. A
sampler thread reads this process's descendants every `period_s`; a process's last reading
counts, so what a process spends after it (at most one period at its very end) is not seen."""

from __future__ import annotations

import os
import threading

_PAGE = os.sysconf("SC_PAGE_SIZE")
_TICK = os.sysconf("SC_CLK_TCK")
# The programs of a run, by their command name (/proc/PID/comm, at most 15 characters).
_KINDS = {"ima-ske": "ske", "ima-canbus": "bus", "ima-dds-node": "dds_agent"}


def _stat(pid: int) -> tuple[int, int, int, bool] | None:
    """(parent pid, CPU ticks, start time, ended: a zombie) of a process."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read()
    except OSError:
        return None
    # the command name may hold spaces and parentheses: fields start after the last ')'
    fields = stat[stat.rindex(b")") + 2:].split()
    return int(fields[1]), int(fields[11]) + int(fields[12]), int(fields[19]), fields[0] == b"Z"


def _comm(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/comm") as f:
            return f.read().strip()
    except OSError:
        return ""


def _kind(pid: int, ppid: int) -> str | None:
    """The kind of a process; None when it cannot be told any more (it is ending: its command
    line is gone)."""
    comm = _comm(pid)
    if _comm(ppid) == "ima-ske":
        return f"partition:{comm}"
    if comm in _KINDS:
        return _KINDS[comm]
    if comm.startswith("python"):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                cmd = f.read()
        except OSError:
            return None
        if not cmd:
            return None
        args = cmd.split(b"\0")
        if b"imaworld" in args:
            return "world"
        if b"ima.recording" in args:
            return "recorder"
        if b"ima" in args and b"launch" in args:
            return "launcher"
        return "other"
    return "other"


def descendants(root: int) -> list[int]:
    kids: dict[int, list[int]] = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            st = _stat(int(name))
            if st is not None:
                kids.setdefault(st[0], []).append(int(name))
    out, stack = [], list(kids.get(root, []))
    while stack:
        pid = stack.pop()
        out.append(pid)
        stack.extend(kids.get(pid, []))
    return out


class Sampler:
    """Samples this process's descendants until stopped: the peak of their summed resident
    memory, and each one's CPU time, kept by kind."""

    def __init__(self, period_s: float = 0.1) -> None:
        self.period_s = period_s
        self.peak = 0
        # (pid, start time): a pid the kernel gives again is another process
        self._ticks: dict[tuple[int, int], tuple[str, int]] = {}  # -> (kind, last CPU ticks)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def _sample(self, me: int) -> None:
        rss = 0
        for pid in descendants(me):
            st = _stat(pid)
            if st is None:
                continue
            # classified anew each time: a process just forked still has its parent's name;
            # but one that is ending (a zombie, or no command line left) keeps its kind
            key = (pid, st[2])
            prev = self._ticks.get(key)
            kind = None if st[3] else _kind(pid, st[0])
            if kind is None:
                kind = prev[0] if prev is not None else "other"
            self._ticks[key] = (kind, st[1])
            try:
                with open(f"/proc/{pid}/statm") as f:
                    rss += int(f.read().split()[1]) * _PAGE
            except (OSError, ValueError, IndexError):
                pass
        self.peak = max(self.peak, rss)

    def _loop(self) -> None:
        me = os.getpid()
        while not self._stop.wait(self.period_s):
            self._sample(me)

    def __enter__(self) -> Sampler:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()

    def cpu_s_by_kind(self) -> dict[str, float]:
        """CPU seconds of each kind of process among the descendants."""
        out: dict[str, float] = {}
        for kind, ticks in self._ticks.values():
            out[kind] = out.get(kind, 0.0) + ticks / _TICK
        return out


def per_emulated_s(cpu_s: dict[str, float], flown_s: float) -> dict[str, float]:
    """CPU milliseconds per emulated second, by kind, largest first, with their `total`."""
    if flown_s <= 0:
        return {}
    ms = {k: round(v * 1000.0 / flown_s, 2) for k, v in cpu_s.items()}
    ms = dict(sorted(ms.items(), key=lambda kv: -kv[1]))
    ms["total"] = round(sum(v * 1000.0 / flown_s for v in cpu_s.values()), 2)
    return ms
