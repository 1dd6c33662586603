# SPDX-License-Identifier: Apache-2.0
"""The CAN frames of a run directory (the bus's trace, can.jsonl), of a recording (run.mcap)
or of any log python-can reads (ASC, BLF, candump .log, TRC, CSV), as one list of Frame, in
time order."""

from __future__ import annotations

import json
import os
import struct
from dataclasses import dataclass
from pathlib import Path

from ima.errors import ImaError

# python-can's readers by file suffix (can.LogReader picks the same ones)
PYCAN_SUFFIXES = (".asc", ".blf", ".log", ".trc", ".csv")


@dataclass(frozen=True, slots=True)
class Frame:
    t_ns: int          # end of the frame on the bus (the time a receiver has it)
    id: int
    extended: bool
    data: bytes
    remote: bool = False
    error: bool = False   # an error frame (the bus's can_error, python-can's is_error_frame)
    sender: str = ""      # the bus client that sent it ("" unknown)
    dlc: int = -1         # its DLC when it differs from len(data) (remote frames)


@dataclass
class Trace:
    """Frames, and what the source says of the bus: bus-off episodes, its bit rate."""

    frames: list[Frame]
    bus_off: list[dict]   # {"t_s", "client", "until_s"} (None: still off at the end)
    source: str
    bitrate: int | None = None
    duration_ns: int | None = None


class BusOff:
    """The bus-off episodes of a bus's events, fed in time order."""

    def __init__(self) -> None:
        self.episodes: list[dict] = []  # {"t_s", "client", "until_s"}
        self._open: dict[str, dict] = {}

    def event(self, t_ns: int, kind, name) -> None:
        if kind == "bus_off":
            ep = self._open[str(name)] = {"t_s": t_ns / 1e9, "client": name, "until_s": None}
            self.episodes.append(ep)
        elif kind == "bus_on" and str(name) in self._open:
            self._open.pop(str(name))["until_s"] = t_ns / 1e9


def load(path: Path) -> Trace:
    """A run directory, its can.jsonl, or a python-can log."""
    path = Path(path)
    if path.is_dir():
        trace = path / "can.jsonl"
        if trace.is_file():
            return _from_bus_trace(trace, _run_bitrate(path))
        if (path / "run.mcap").is_file():
            return _from_mcap(path / "run.mcap", _run_bitrate(path))
        raise ImaError(f"{path}: no can.jsonl or run.mcap (not a run directory of ima fly or "
                       "ima launch)")
    if not path.is_file():
        raise ImaError(f"{path}: no such file or directory")
    if path.suffix == ".mcap":
        return _from_mcap(path, _run_bitrate(path.parent))
    if path.name.endswith(".jsonl"):
        return _from_bus_trace(path, _run_bitrate(path.parent))
    if path.suffix.lower() in PYCAN_SUFFIXES:
        return _from_pycan(path)
    raise ImaError(f"{path}: not a run directory, can.jsonl or a log python-can reads "
                   f"({', '.join(PYCAN_SUFFIXES)})")


def _run_bitrate(run_dir: Path) -> int | None:
    """The bus's bit rate, from the run's command line (launch.json)."""
    try:
        cmd = json.loads((run_dir / "launch.json").read_text())["commands"]["canbus"]
        return int(cmd[cmd.index("--bitrate") + 1])
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return None


def _from_bus_trace(path: Path, bitrate: int | None) -> Trace:
    frames: list[Frame] = []
    off = BusOff()
    end = 0
    try:
        f = open(path, "rb")  # noqa: SIM115 - closed below
    except OSError as e:
        raise ImaError(f"{path}: {e.strerror}") from e
    with f:
        for line in f:
            if b'"can_' not in line and b'"bus_o' not in line:
                continue  # a cheap filter before parsing: most lines are frames anyway
            try:
                r = json.loads(line)
            except ValueError:
                continue  # a line cut by a killed writer
            kind, t = r.get("kind"), r.get("t_ns", 0)
            end = max(end, t)
            if kind in ("can_tx", "can_error"):
                data = bytes.fromhex(r.get("data", "")) if kind == "can_tx" else b""
                remote = bool(r.get("rtr"))
                frames.append(Frame(t, int(r["id"]), bool(r.get("ext")), data, remote,
                                    kind == "can_error", str(r.get("from", "")),
                                    int(r.get("len", len(data))) if remote else -1))
            else:
                off.event(t, kind, r.get("name"))
    frames.sort(key=lambda fr: fr.t_ns)
    return Trace(frames, off.episodes, str(path), bitrate, end or None)


def _from_mcap(path: Path, bitrate: int | None) -> Trace:
    """The frames of a recording's /can/frames channel, its bus-off episodes from
    /can/events (docs/recording.md)."""
    import orjson
    from mcap.exceptions import McapError

    from ima.recording import mcapread

    frames: list[Frame] = []
    off = BusOff()
    end = 0
    try:
        for topic, _, raw in mcapread.messages(path, ["/can/frames", "/can/events"]):
            r = orjson.loads(raw)
            t = r.get("t_ns", 0)
            end = max(end, t)
            if topic == "/can/frames":
                error = bool(r.get("error"))
                data = b"" if error else bytes.fromhex(r.get("data", ""))
                remote = bool(r.get("rtr"))
                frames.append(Frame(t, int(r["id"]), bool(r.get("ext")), data, remote, error,
                                    str(r.get("from", "")),
                                    int(r.get("len", 0)) if remote else -1))
            else:
                off.event(t, r.get("kind"), r.get("name"))
    except (OSError, ValueError, struct.error, McapError) as e:
        raise ImaError(f"{path}: not a readable recording: {e}") from e
    frames.sort(key=lambda fr: fr.t_ns)
    return Trace(frames, off.episodes, str(path), bitrate, end or None)


def _from_pycan(path: Path) -> Trace:
    import can

    frames: list[Frame] = []
    t0 = None
    try:
        reader = can.LogReader(os.fspath(path))
        for m in reader:
            t = round(m.timestamp * 1e9)
            t0 = t if t0 is None else t0
            frames.append(Frame(t - t0, int(m.arbitration_id), bool(m.is_extended_id),
                                bytes(m.data) if not m.is_remote_frame else b"",
                                bool(m.is_remote_frame), bool(m.is_error_frame),
                                str(m.channel) if m.channel is not None else "",
                                m.dlc if m.is_remote_frame else -1))
    except Exception as e:  # noqa: BLE001 - python-can's readers raise whatever they meet
        raise ImaError(f"{path}: python-can cannot read it: {type(e).__name__}: {e}") from e
    frames.sort(key=lambda fr: fr.t_ns)
    return Trace(frames, [], str(path), None, frames[-1].t_ns if frames else None)
