# SPDX-License-Identifier: Apache-2.0
"""The recording's messages from the lines of a run's traces (docs/recording.md): each
trace's lines become messages on their topics, handed to `out.put(topic, schema name, schema,
t_ns, payload, number)`. The same conversion makes run.mcap at the end of a run (write.py)
and serves a live run (ima.websocket), which feeds each trace's lines as they are written:
what a trace's messages need from its earlier lines (the truth's origin) is kept between
feeds.

A line is numbered from 0 in its trace (the message's sequence number); a cut or garbled line
is left out and counted in `skipped` under its trace's name."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from functools import partial
from pathlib import Path

import orjson

from ima.recording import schemas
from ima.recording.follow import Block

_FT = 0.3048
_T_PREFIX = b'{"t_ns":'
_SKE_TOPICS = {b"window_start": "schedule", b"window_end": "schedule", b"hm": "hm"}

Lines = Iterable[tuple[int, bytes]]  # (number, line without its newline)


def _by_lines(feed: Callable[[Lines], None]) -> Callable[[Block], None]:
    return lambda block: feed(block.lines())


def _arinc825(can_id: int) -> dict:
    # LCC (3) | FID (7) | RSD (1) | LCL (1) | PVT (1) | DOC (14) | RCI (2)
    return {"lcc": (can_id >> 26) & 0x7, "fid": (can_id >> 19) & 0x7F,
            "doc": (can_id >> 2) & 0x3FFF, "rci": can_id & 0x3}


def _quaternion(roll: float, pitch: float, yaw: float) -> dict:
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return {"w": cr * cp * cy + sr * sp * sy, "x": sr * cp * cy - cr * sp * sy,
            "y": cr * sp * cy + sr * cp * sy, "z": cr * cp * sy - sr * sp * cy}


class Topics:
    def __init__(self, out) -> None:
        self.out = out
        self.skipped: dict[str, int] = {}
        self._origin: tuple[float, float] | None = None  # the truth's first position
        self._extra_of: dict[tuple, bytes] = {}  # a frame's added fields, by id and kind
        self._sig: dict[str, tuple] = {}  # a message's topic, schema name, schema, signals

    def traces(self, run_dir: Path, nodes: list[str]) -> list[tuple[Path, Callable[[Block], None]]]:
        """Every line-based trace of a run with what takes its blocks of lines
        (recording/follow.py), in the recording's order."""
        run_dir = Path(run_dir)
        out = [(run_dir / "can.jsonl", self.can)]
        for k, node in enumerate(nodes, start=1):
            out.append((run_dir / f"{node}.jsonl", partial(self.ske, node)))
            out.append((run_dir / f"dds{k}.jsonl", partial(self.dds, node, f"dds{k}.jsonl")))
        out.append((run_dir / "world.jsonl", self.world))
        out.append((run_dir / "truth.jsonl", self.truth))
        return [(path, _by_lines(feed)) for path, feed in out]

    def _signals(self, msg) -> tuple[str, str, bytes, tuple[str, ...]]:
        """The topic, schema name, schema and signal names of a DBC message's signals."""
        sig = self._sig.get(msg.name)
        if sig is None:
            sig = self._sig[msg.name] = (f"/can/signals/{msg.name}", f"ima.can.{msg.name}",
                                         schemas.signals(msg.name, msg.signal_names),
                                         msg.signal_names)
        return sig

    def topics(self, nodes: list[str]) -> list[tuple[str, str, bytes]]:
        """(topic, schema name, schema) of every topic the traces can give messages on (a live
        server advertises them all before the run starts)."""
        from ima.canbus import codec

        out = [("/can/frames", "ima.CanFrame", schemas.CAN_FRAME),
               ("/can/events", "ima.BusEvent", schemas.BUS_EVENT)]
        seen = set()
        for msg in codec.BY_ID.values():
            if msg.name not in seen:
                seen.add(msg.name)
                out.append(self._signals(msg)[:3])
        for node in nodes:
            out += [(f"/{node}/{v}", "ima.SkeEvent", schemas.SKE_EVENT)
                    for v in ("schedule", "hm", "events")]
            out.append((f"/{node}/dds", "ima.DdsEvent", schemas.DDS_EVENT))
        return out + [("/vote", "ima.WorldEvent", schemas.WORLD_EVENT),
                      ("/world/events", "ima.WorldEvent", schemas.WORLD_EVENT),
                      ("/world/truth", "ima.Truth", schemas.TRUTH),
                      ("/world/location", "foxglove.LocationFix", schemas.LOCATION_FIX),
                      ("/world/pose", "foxglove.PoseInFrame", schemas.POSE_IN_FRAME)]

    # ---- reading lines ---------------------------------------------------------------------

    def _skip(self, name: str) -> None:
        self.skipped[name] = self.skipped.get(name, 0) + 1

    def _parsed(self, lines: Lines, name: str):
        """(number, line, record) of JSON lines; a line that is not a JSON object with an
        integer time (if any) is skipped."""
        for i, line in lines:
            try:
                rec = orjson.loads(line)
            except orjson.JSONDecodeError:
                self._skip(name)
                continue
            t = rec.get("t_ns", 0) if isinstance(rec, dict) else None
            if type(t) is int and t < 1 << 64:
                yield i, line, rec
            else:
                self._skip(name)

    def _raw(self, lines: Lines, name: str):
        """(number, line, t_ns, kind) of lines starting with {"t_ns":N, (the SKE's), read
        without parsing the JSON; a cut line (no closing brace) is skipped."""
        for i, line in lines:
            comma = line.find(b",", 8)
            if not line.startswith(_T_PREFIX) or not line.endswith(b"}") or comma < 0:
                self._skip(name)
                continue
            try:
                t = int(line[8:comma])
            except ValueError:
                self._skip(name)
                continue
            k = line.find(b'"kind":"')
            kind = line[k + 8:line.find(b'"', k + 8)] if k >= 0 else b""
            yield i, line, t, kind

    # ---- the traces ------------------------------------------------------------------------

    def can(self, lines: Lines) -> None:
        """The bus's trace: frames (with their ARINC 825 fields and DBC name), each message's
        decoded signals on its own topic, and the bus's events."""
        from ima.canbus import codec

        event_schema = schemas.BUS_EVENT
        put, by_id, dumps = self.out.put, codec.BY_ID, orjson.dumps
        extra_of = self._extra_of
        signals = self._signals
        for i, line, r in self._parsed(lines, "can.jsonl"):
            kind, t = r.get("kind"), r.get("t_ns", 0)
            if kind not in ("can_tx", "can_error"):
                put("/can/events", "ima.BusEvent", event_schema, t, line, i)
                continue
            cid = r.get("id", 0)
            if type(cid) is not int:  # a garbled identifier
                self._skip("can.jsonl")
                continue
            key = (cid, kind, bool(r.get("ext")))
            extra = extra_of.get(key)
            msg = by_id.get(cid) if kind == "can_tx" else None
            if extra is None:
                fields = {"error": kind == "can_error", "name": msg.name if msg else None}
                if key[2]:
                    fields.update(_arinc825(int(cid)))
                extra = extra_of[key] = b"," + dumps(fields)[1:-1]
            # the bus's own line, with the decoded fields and its record number added
            put("/can/frames", "ima.CanFrame", schemas.CAN_FRAME, t,
                line.rstrip()[:-1] + extra + b',"seq":' + str(i).encode() + b"}", i)
            if msg is not None and not r.get("rtr"):
                try:
                    values = msg.decode(bytes.fromhex(r.get("data", "")))
                except (ValueError, IndexError, TypeError):  # not hex, not a string
                    continue
                topic, schema_name, schema, names = signals(msg)
                rec = dict(zip(names, values, strict=True))
                rec["t_ns"] = t
                rec["from"] = r.get("from")
                put(topic, schema_name, schema, t, dumps(rec), i)

    def ske(self, node: str, lines: Lines) -> None:
        """A node's SKE trace: its schedule, its health monitor's events, the rest."""
        schema = schemas.SKE_EVENT
        topics = {k: f"/{node}/{v}" for k, v in _SKE_TOPICS.items()}
        other = f"/{node}/events"
        put = self.out.put
        for i, line, t, kind in self._raw(lines, f"{node}.jsonl"):
            put(topics.get(kind, other), "ima.SkeEvent", schema, t, line, i)

    def dds(self, node: str, name: str, lines: Lines) -> None:
        schema = schemas.DDS_EVENT
        for i, line, r in self._parsed(lines, name):  # few: parsed
            self.out.put(f"/{node}/dds", "ima.DdsEvent", schema, r.get("t_ns", 0), line, i)

    def world(self, lines: Lines) -> None:
        schema = schemas.WORLD_EVENT
        for i, line, r in self._parsed(lines, "world.jsonl"):
            topic = "/vote" if r.get("kind") in ("vote", "voted_out") else "/world/events"
            self.out.put(topic, "ima.WorldEvent", schema, r.get("t_ns", 0), line, i)

    def truth(self, lines: Lines) -> None:
        """The world's truth, and from it the aircraft's position (LocationFix, for the map)
        and pose in a local frame at its first position (PoseInFrame, for the 3D view)."""
        put = self.out.put
        for i, line, r in self._parsed(lines, "truth.jsonl"):
            t = r.get("t_ns", 0)
            put("/world/truth", "ima.Truth", schemas.TRUTH, t, line, i)
            lat, lon, alt = r.get("lat_deg"), r.get("lon_deg"), r.get("alt_ft")
            if not all(isinstance(x, (int, float)) for x in (lat, lon, alt)):
                continue
            stamp = {"sec": t // 1_000_000_000, "nsec": t % 1_000_000_000}
            put("/world/location", "foxglove.LocationFix", schemas.LOCATION_FIX, t,
                orjson.dumps({"timestamp": stamp, "frame_id": "aircraft", "latitude": lat,
                              "longitude": lon, "altitude": alt * _FT,
                              "position_covariance": [0.0] * 9,
                              "position_covariance_type": 0}), i)
            if self._origin is None:
                self._origin = (lat, lon)
            origin = self._origin
            # a local ENU frame at the start; the body FLU: roll, -pitch, yaw = 90° - heading
            east = (lon - origin[1]) * 111_320.0 * math.cos(math.radians(origin[0]))
            north = (lat - origin[0]) * 110_540.0
            q = _quaternion(math.radians(r.get("roll_deg") or 0.0),
                            -math.radians(r.get("pitch_deg") or 0.0),
                            math.radians(90.0 - (r.get("heading_deg") or 0.0)))
            put("/world/pose", "foxglove.PoseInFrame", schemas.POSE_IN_FRAME, t,
                orjson.dumps({"timestamp": stamp, "frame_id": "start",
                              "pose": {"position": {"x": east, "y": north, "z": alt * _FT},
                                       "orientation": q}}), i)
