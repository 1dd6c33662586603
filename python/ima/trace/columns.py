# SPDX-License-Identifier: Apache-2.0
"""The CAN frames of a trace as columns (numpy arrays), for the analyses that take every frame
of a long recording at once (`ima trace stats`). Read fast where the source allows it:

- a recording (run.mcap): each chunk holding /can/frames is decompressed and scanned whole by
  one regular expression for the fields the statistics need; the number of matches is checked
  against the chunk's message index, and a chunk where they differ is read message by message
  instead (nothing is dropped silently);
- a BLF or ASC log of classic CAN: our own readers (blf.py, asc.py), which hand a log they do
  not fully recognise to python-can's;
- any other python-can log: python-can's reader, its messages' fields into one array;
- anything else: source.load()'s frames, converted.
"""

from __future__ import annotations

import os
import re
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ima.errors import ImaError
from ima.trace import source

# A /can/frames message: the bus's trace line (nodes/src/bus_trace.c) with fields added after.
_FRAME = re.compile(
    rb'\{"t_ns":(-?\d+),"node":"canbus","src":"canbus","kind":"can_(t|e)[a-z]*",'
    rb'"start_ns":-?\d+,"id":(\d+),"ext":(t|f)[a-z]*(,"rtr":true)?,"len":(\d+)'
    rb'(?:,"data":"([0-9a-fA-F]*)")?')
_NIBBLE = np.zeros(256, dtype=np.uint8)
for _i, _c in enumerate(b"0123456789abcdef"):
    _NIBBLE[_c] = _i
for _i, _c in enumerate(b"ABCDEF"):
    _NIBBLE[_c] = 10 + _i


@dataclass
class Columns:
    """n frames in time order; error frames included (`error`), their data empty."""

    t_ns: np.ndarray    # int64: the end of the frame on the bus
    id: np.ndarray      # int64
    ext: np.ndarray     # bool
    rtr: np.ndarray     # bool
    error: np.ndarray   # bool
    dlen: np.ndarray    # int64: bytes of data on the wire (0 for remote and error frames)
    data: np.ndarray    # uint8 (n, 8): the data, zero beyond dlen
    bus_off: list[dict]
    source: str
    bitrate: int | None = None
    duration_ns: int | None = None

    def __len__(self) -> int:
        return len(self.t_ns)

    def sorted(self) -> Columns:
        """In time order (a stable sort: frames of equal time keep the source's order)."""
        if len(self.t_ns) < 2 or bool(np.all(self.t_ns[1:] >= self.t_ns[:-1])):
            return self
        o = np.argsort(self.t_ns, kind="stable")
        return Columns(self.t_ns[o], self.id[o], self.ext[o], self.rtr[o], self.error[o],
                       self.dlen[o], self.data[o], self.bus_off, self.source, self.bitrate,
                       self.duration_ns)


def _make(t, ids, ext, rtr, err, dlen, data, bus_off, src, bitrate, duration) -> Columns:
    return Columns(np.asarray(t, dtype=np.int64), np.asarray(ids, dtype=np.int64),
                   np.asarray(ext, dtype=bool), np.asarray(rtr, dtype=bool),
                   np.asarray(err, dtype=bool), np.asarray(dlen, dtype=np.int64), data,
                   bus_off, src, bitrate, duration).sorted()


def _data8(payloads: list[bytes]) -> np.ndarray:
    """(n, 8) uint8 from data of at most 8 bytes each."""
    if not payloads:
        return np.zeros((0, 8), dtype=np.uint8)
    return np.array(payloads, dtype="S8").view(np.uint8).reshape(-1, 8)


def _hex8(hexes: list[bytes]) -> np.ndarray:
    """(n, 8) uint8 from hex strings of at most 16 digits (NUL-padded: zero)."""
    if not hexes:
        return np.zeros((0, 8), dtype=np.uint8)
    digits = _NIBBLE[np.frombuffer(np.array(hexes, dtype="S16").tobytes(),
                                   dtype=np.uint8)].reshape(-1, 8, 2)
    return (digits[:, :, 0] << 4) | digits[:, :, 1]


def of_frames(frames: list[source.Frame], bus_off, src, bitrate, duration) -> Columns:
    data = [b"" if f.error or f.remote else f.data[:8] for f in frames]
    return _make([f.t_ns for f in frames], [f.id for f in frames],
                 [f.extended for f in frames], [f.remote for f in frames],
                 [f.error for f in frames], [len(d) for d in data], _data8(data), bus_off,
                 src, bitrate, duration)


def of_trace(trace: source.Trace) -> Columns:
    return of_frames(trace.frames, trace.bus_off, trace.source, trace.bitrate,
                     trace.duration_ns)


def load(path: Path) -> Columns:
    """The columns of a run directory, recording, can.jsonl or python-can log (as
    source.load takes them)."""
    path = Path(path)
    mcap = None
    if path.is_dir() and not (path / "can.jsonl").is_file() and (path / "run.mcap").is_file():
        mcap, run_dir = path / "run.mcap", path
    elif path.is_file() and path.suffix == ".mcap":
        mcap, run_dir = path, path.parent
    if mcap is not None:
        cols = _from_mcap(mcap, source._run_bitrate(run_dir))
        if cols is not None:
            return cols
    elif path.is_file() and path.suffix.lower() in source.PYCAN_SUFFIXES:
        return _from_pycan(path)
    return of_trace(source.load(path))


def _from_mcap(path: Path, bitrate: int | None) -> Columns | None:
    """None where the file has no index to scan by (source.load reads it then)."""
    from mcap.exceptions import McapError

    from ima.recording import mcapread

    try:
        chunks = mcapread.chunks(path, ["/can/frames"])
        if chunks is None:
            return None
        parts = []
        for records, count in chunks:
            found = _FRAME.findall(records)
            if len(found) != count:
                return None  # not the bus's lines as this reader knows them: read them whole
            parts += found
        bus_off, end = _events(path)
    except (OSError, ValueError, struct.error, McapError) as e:
        raise ImaError(f"{path}: not a readable recording: {e}") from e
    if not parts:
        return _make([], [], [], [], [], [], _data8([]), bus_off, str(path), bitrate, end or None)
    t, kind, ids, ext, rtr, length, hexes = zip(*parts, strict=True)
    t = np.array(t, dtype="S20").astype(np.int64)
    err = np.array(kind) == b"e"
    rtr = np.array(rtr) != b""
    data = _hex8(list(hexes))
    length = np.array(length, dtype="S3").astype(np.int64)
    if bool((length > 8).any()):
        return None  # not classic CAN: read message by message
    dlen = np.where(err | rtr, 0, length)
    end = max(end, int(t.max()))
    return _make(t, np.array(ids, dtype="S10").astype(np.int64), np.array(ext) == b"t", rtr,
                 err, dlen, data, bus_off, str(path), bitrate, end or None)


def _events(path: Path) -> tuple[list[dict], int]:
    """The bus-off episodes of a recording's /can/events, and its last event's time."""
    import orjson

    from ima.recording import mcapread

    off = source.BusOff()
    end = 0
    for _, _, raw in mcapread.messages(path, ["/can/events"]):
        r = orjson.loads(raw)
        t = r.get("t_ns", 0)
        end = max(end, t)
        off.event(t, r.get("kind"), r.get("name"))
    return off.episodes, end


_ROW = np.dtype([("t", "f8"), ("id", "i8"), ("ext", "?"), ("rtr", "?"), ("err", "?"),
                 ("data", "S8"), ("dlen", "i8")])


def _from_pycan(path: Path) -> Columns:
    """A log through python-can's reader (a BLF or ASC of classic CAN through our own:
    blf.py, asc.py)."""
    suffix = path.suffix.lower()
    if suffix in (".blf", ".asc"):
        from ima.trace import asc, blf

        try:
            got = (blf if suffix == ".blf" else asc).read(path)
        except (OSError, ValueError, struct.error) as e:
            raise ImaError(f"{path}: not a readable log: {type(e).__name__}: {e}") from e
        if got is not None:
            t, ids, ext, rtr, err, data = got
            return _columns(np.asarray(t, dtype=np.int64), ids, ext, rtr, err, data, path)
    import can

    try:
        rows = np.fromiter(((m.timestamp, m.arbitration_id, m.is_extended_id,
                             m.is_remote_frame, m.is_error_frame, bytes(m.data[:8]), len(m.data))
                            for m in can.LogReader(os.fspath(path))), dtype=_ROW)
    except Exception as e:  # noqa: BLE001 - python-can's readers raise whatever they meet
        raise ImaError(f"{path}: python-can cannot read it: {type(e).__name__}: {e}") from e
    ts = np.round(rows["t"] * 1e9).astype(np.int64)
    return _columns(ts, rows["id"], rows["ext"], rows["rtr"], rows["err"],
                    rows["data"], path, rows["dlen"])


def _columns(ts, ids, ext, rtr, err, data, path: Path, dlen=None) -> Columns:
    """Columns from a log's fields: times from the first frame's, no data kept for remote and
    error frames (as source.load gives them)."""
    ts = np.asarray(ts, dtype=np.int64)
    if len(ts):
        ts = ts - ts[0]
    rtr, err = np.asarray(rtr, dtype=bool), np.asarray(err, dtype=bool)
    data8 = np.ascontiguousarray(np.asarray(data, dtype="S8")).view(np.uint8).reshape(-1, 8).copy()
    if dlen is None:
        dlen = np.fromiter(map(len, data), dtype=np.int64, count=len(data))
    none = rtr | err
    data8[none] = 0
    dlen = np.where(none, 0, np.minimum(np.asarray(dlen, dtype=np.int64), 8))
    return _make(ts, ids, ext, rtr, err, dlen, data8, [], str(path), None,
                 int(ts.max()) if len(ts) else None)
