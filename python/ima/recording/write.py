# SPDX-License-Identifier: Apache-2.0
"""RUN_DIR/run.mcap from the traces a run leaves (docs/recording.md).

The recording is made from the producers' own traces once the run has ended (after Ctrl-C
as well: every trace is complete up to the stop), or from whatever a killed run left
(`ima trace recover`): a line cut by the kill is skipped and counted. Each message's log
time is the record's emulated time (t_ns); its sequence number is the record's number (its
line, from 0) in its producer's trace, so a reader can check that nothing was dropped. The
file is written beside as run.mcap.part and renamed when complete.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import orjson

from ima.errors import ImaError
from ima.recording import schemas

NAME = "run.mcap"
CHUNK_BYTES = 1 << 20
_FT = 0.3048


class _Out:
    """The MCAP writer with its schemas and channels, registered on first use."""

    def __init__(self, f) -> None:
        from ima.recording.mcapfile import McapWriter

        self.w = McapWriter(f, chunk_bytes=CHUNK_BYTES)
        self.schemas: dict[str, int] = {}
        self.channels: dict[str, int] = {}

    def channel(self, topic: str, schema_name: str, schema: bytes) -> int:
        ch = self.channels.get(topic)
        if ch is None:
            sid = self.schemas.get(schema_name)
            if sid is None:
                sid = self.schemas[schema_name] = len(self.schemas) + 1
                self.w.schema(sid, schema_name, "jsonschema", schema)
            ch = self.channels[topic] = len(self.channels) + 1
            self.w.channel(ch, sid, topic, "json")
        return ch

    @property
    def counts(self) -> dict[str, int]:
        return {t: self.w.counts[c] for t, c in self.channels.items()}

    def put(self, topic: str, schema_name: str, schema: bytes, t_ns: int, data: bytes,
            seq: int) -> None:
        ch = self.channels.get(topic) or self.channel(topic, schema_name, schema)
        self.w.message(ch, seq, t_ns if t_ns > 0 else 0, data)


def _numbered(path: Path):
    """(number, line without its newline) of a trace; nothing if it cannot be read."""
    try:
        f = open(path, "rb")  # noqa: SIM115 - closed below
    except OSError:
        return
    with f:
        for i, line in enumerate(f):
            yield i, line.rstrip(b"\n")


def _lines(path: Path, skipped: dict[str, int]):
    """(number, line bytes, record) of a JSON-lines trace; a cut or garbled line is counted in
    skipped[path.name] and left out."""
    for i, line in _numbered(path):
        try:
            rec = orjson.loads(line)
        except orjson.JSONDecodeError:
            skipped[path.name] = skipped.get(path.name, 0) + 1
            continue
        if isinstance(rec, dict):
            yield i, line, rec
        else:
            skipped[path.name] = skipped.get(path.name, 0) + 1


def _arinc825(can_id: int) -> dict:
    # LCC (3) | FID (7) | RSD (1) | LCL (1) | PVT (1) | DOC (14) | RCI (2)
    return {"lcc": (can_id >> 26) & 0x7, "fid": (can_id >> 19) & 0x7F,
            "doc": (can_id >> 2) & 0x3FFF, "rci": can_id & 0x3}


def _can(out: _Out, run_dir: Path, skipped: dict) -> None:
    from ima.canbus import codec

    sig_schema: dict[str, bytes] = {}
    event_schema = schemas.event("ima.BusEvent", "The CAN bus's events: clients, faults, "
                                                 "bus-off, stop")
    put, by_id, dumps = out.put, codec.BY_ID, orjson.dumps
    extra_of: dict[tuple, bytes] = {}  # the fields a frame gains, by identifier and kind
    for i, line, r in _lines(run_dir / "can.jsonl", skipped):
        kind, t = r.get("kind"), r.get("t_ns", 0)
        if kind not in ("can_tx", "can_error"):
            put("/can/events", "ima.BusEvent", event_schema, t, line, i)
            continue
        cid = r.get("id", 0)
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
            line[:-1] + extra + b',"seq":' + str(i).encode() + b"}", i)
        if msg is not None and not r.get("rtr"):
            try:
                values = msg.decode(bytes.fromhex(r.get("data", "")))
            except (ValueError, IndexError):
                continue
            schema = sig_schema.get(msg.name)
            if schema is None:
                schema = sig_schema[msg.name] = schemas.signals(msg.name, msg.signal_names)
            put(f"/can/signals/{msg.name}", f"ima.can.{msg.name}", schema, t,
                dumps(dict(zip(msg.signal_names, values, strict=True)) | {
                    "t_ns": t, "from": r.get("from")}), i)


_T_PREFIX = b'{"t_ns":'


def _raw_lines(path: Path, skipped: dict[str, int]):
    """(number, line, t_ns, kind) of a trace whose lines start with {"t_ns":N, (the SKE's, the
    agents'): read without parsing the JSON; a cut line (no closing brace) is counted and
    left out."""
    for i, line in _numbered(path):
        comma = line.find(b",", 8)
        if not line.startswith(_T_PREFIX) or not line.endswith(b"}") or comma < 0:
            skipped[path.name] = skipped.get(path.name, 0) + 1
            continue
        try:
            t = int(line[8:comma])
        except ValueError:
            skipped[path.name] = skipped.get(path.name, 0) + 1
            continue
        k = line.find(b'"kind":"')
        kind = line[k + 8:line.find(b'"', k + 8)] if k >= 0 else b""
        yield i, line, t, kind


_SKE_TOPICS = {b"window_start": "schedule", b"window_end": "schedule", b"hm": "hm"}


def _ske(out: _Out, run_dir: Path, node: str, skipped: dict) -> None:
    schema = schemas.event("ima.SkeEvent", "A node's SKE trace record (docs/trace-format.md)")
    topics = {k: f"/{node}/{v}" for k, v in _SKE_TOPICS.items()}
    other = f"/{node}/events"
    put = out.put
    for i, line, t, kind in _raw_lines(run_dir / f"{node}.jsonl", skipped):
        put(topics.get(kind, other), "ima.SkeEvent", schema, t, line, i)


def _dds(out: _Out, run_dir: Path, k: int, node: str, skipped: dict) -> None:
    schema = schemas.event("ima.DdsEvent", "A DDS agent's trace record (emulated t_ns, wall "
                                           "t_wall_ns)")
    for i, line, r in _lines(run_dir / f"dds{k}.jsonl", skipped):  # few: parsed
        out.put(f"/{node}/dds", "ima.DdsEvent", schema, r.get("t_ns", 0), line, i)


def _world(out: _Out, run_dir: Path, skipped: dict) -> None:
    schema = schemas.event("ima.WorldEvent", "The world's events: actuators, votes, pilot, "
                                             "faults")
    for i, line, r in _lines(run_dir / "world.jsonl", skipped):
        topic = "/vote" if r.get("kind") in ("vote", "voted_out") else "/world/events"
        out.put(topic, "ima.WorldEvent", schema, r.get("t_ns", 0), line, i)


def _quaternion(roll: float, pitch: float, yaw: float) -> dict:
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return {"w": cr * cp * cy + sr * sp * sy, "x": sr * cp * cy - cr * sp * sy,
            "y": cr * sp * cy + sr * cp * sy, "z": cr * cp * sy - sr * sp * cy}


def _truth(out: _Out, run_dir: Path, skipped: dict) -> None:
    origin = None
    for i, line, r in _lines(run_dir / "truth.jsonl", skipped):
        t = r.get("t_ns", 0)
        out.put("/world/truth", "ima.Truth", schemas.TRUTH, t, line, i)
        lat, lon, alt = r.get("lat_deg"), r.get("lon_deg"), r.get("alt_ft")
        if not all(isinstance(x, (int, float)) for x in (lat, lon, alt)):
            continue
        stamp = {"sec": t // 1_000_000_000, "nsec": t % 1_000_000_000}
        out.put("/world/location", "foxglove.LocationFix", schemas.LOCATION_FIX, t,
                orjson.dumps({"timestamp": stamp, "frame_id": "aircraft", "latitude": lat,
                              "longitude": lon, "altitude": alt * _FT,
                              "position_covariance": [0.0] * 9,
                              "position_covariance_type": 0}), i)
        if origin is None:
            origin = (lat, lon)
        # a local ENU frame at the start; the body FLU: roll, -pitch, yaw = 90 deg - heading
        east = (lon - origin[1]) * 111_320.0 * math.cos(math.radians(origin[0]))
        north = (lat - origin[0]) * 110_540.0
        q = _quaternion(math.radians(r.get("roll_deg") or 0.0),
                        -math.radians(r.get("pitch_deg") or 0.0),
                        math.radians(90.0 - (r.get("heading_deg") or 0.0)))
        out.put("/world/pose", "foxglove.PoseInFrame", schemas.POSE_IN_FRAME, t,
                orjson.dumps({"timestamp": stamp, "frame_id": "start",
                              "pose": {"position": {"x": east, "y": north, "z": alt * _FT},
                                       "orientation": q}}), i)


def _fdr(out: _Out, run_dir: Path, node: str) -> None:
    path = run_dir / f"{node}.fdr"
    if not path.is_file():
        return
    from ima.fdr import records

    try:
        rec = records.read(path)
    except OSError:
        return
    allrec = sorted([("start", r) for r in rec.starts] + [("frame", r) for r in rec.frames]
                    + [("hm", r) for r in rec.hm], key=lambda kr: kr[1]["offset"])
    for i, (kind, r) in enumerate(allrec):
        out.put(f"/{node}/fdr", "ima.FdrRecord", schemas.FDR, r.get("t_ns") or 0,
                orjson.dumps({"kind": kind, **r}, default=str), i)


def _verdicts(out: _Out, run_dir: Path, launch: dict) -> None:
    for i, f in enumerate(launch.get("faults") or []):
        t = round(float(f.get("t_s") or 0) * 1e9)
        out.put("/faults", "ima.Fault", schemas.event("ima.Fault", "A fault the run injects"),
                t, orjson.dumps(f), i)
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return
    if summary.get("oracles"):
        t = round(float(summary.get("flown_s") or 0) * 1e9)
        judged = {k: summary.get(k) for k in ("outcome", "oracles", "violations", "faults",
                                              "golden") if k in summary}
        out.put("/oracles", "ima.Verdicts", schemas.VERDICT, t,
                orjson.dumps(judged, default=str), 0)


def _metadata(out: _Out, run_dir: Path, launch: dict) -> None:
    from ima import provenance

    meta = {k: json.dumps(launch.get(k)) for k in ("kind", "system", "nodes", "seed",
                                                   "duration_s", "pilot", "dds_domain",
                                                   "faults", "commands") if k in launch}
    try:
        prov = json.loads((run_dir / "summary.json").read_text()).get("provenance")
    except (OSError, ValueError):
        prov = None
    meta["provenance"] = json.dumps(prov or provenance.provenance())
    out.w.metadata("ima.run", meta)


def record(run_dir: Path, output: Path | None = None, before_verdicts=None) -> dict:
    """Writes the recording of run_dir; returns its counts: messages per topic, lines skipped
    (cut by a kill). `before_verdicts()` is called once the traces are in, before the
    summary's verdicts are read (the launcher's recorder waits there for the summary)."""
    run_dir = Path(run_dir)
    if not (run_dir / "can.jsonl").exists() and not (run_dir / "truth.jsonl").exists():
        raise ImaError(f"{run_dir}: not a run directory (no can.jsonl, no truth.jsonl)")
    output = Path(output) if output else run_dir / NAME
    try:
        launch = json.loads((run_dir / "launch.json").read_text())
    except (OSError, ValueError):
        launch = {}
    nodes = list(launch.get("nodes") or sorted(
        p.stem for p in run_dir.glob("node*.jsonl") if p.stem[4:].isdigit()))
    part = output.with_name(output.name + ".part")
    skipped: dict[str, int] = {}
    try:
        with open(part, "w+b") as f:
            out = _Out(f)
            _metadata(out, run_dir, launch)
            _can(out, run_dir, skipped)
            for k, node in enumerate(nodes, start=1):
                _ske(out, run_dir, node, skipped)
                _dds(out, run_dir, k, node, skipped)
                _fdr(out, run_dir, node)
            _world(out, run_dir, skipped)
            _truth(out, run_dir, skipped)
            if before_verdicts is not None:
                before_verdicts()
            _verdicts(out, run_dir, launch)
            out.w.finish()
        os.replace(part, output)
    except OSError as e:
        part.unlink(missing_ok=True)
        raise ImaError(f"{output}: cannot write the recording: {e.strerror}") from e
    return {"file": str(output), "bytes": output.stat().st_size, "topics": out.counts,
            "skipped_lines": skipped}
