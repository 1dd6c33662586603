# SPDX-License-Identifier: Apache-2.0
"""The JSON schemas of the recording's channels (jsonschema encoding: Foxglove shows the
fields and plots them)."""

from __future__ import annotations

import json

_TIME = {"type": "object", "properties": {"sec": {"type": "integer"},
                                          "nsec": {"type": "integer"}}}


def _obj(title: str, props: dict, description: str) -> bytes:
    return json.dumps({"title": title, "description": description, "type": "object",
                       "properties": props}).encode()


def event(title: str, description: str) -> bytes:
    """A trace record: its common fields; the others depend on its kind (docs/trace-format.md)."""
    return _obj(title, {"t_ns": {"type": "integer"}, "node": {"type": "string"},
                        "src": {"type": "string"}, "kind": {"type": "string"}}, description)


CAN_FRAME = _obj("ima.CanFrame", {
    "t_ns": {"type": "integer", "description": "end of the frame on the bus (emulated ns)"},
    "start_ns": {"type": "integer"},
    "id": {"type": "integer"}, "ext": {"type": "boolean"}, "rtr": {"type": "boolean"},
    "len": {"type": "integer"}, "data": {"type": "string", "description": "hex"},
    "from": {"type": "string", "description": "the sending client"},
    "error": {"type": "boolean", "description": "an error frame"},
    "name": {"type": "string", "description": "the DBC message"},
    "lcc": {"type": "integer", "description": "ARINC 825 logical communication channel"},
    "fid": {"type": "integer", "description": "ARINC 825 function code"},
    "doc": {"type": "integer", "description": "ARINC 825 data object code"},
    "rci": {"type": "integer", "description": "ARINC 825 redundancy channel identifier"},
    "seq": {"type": "integer", "description": "the record's number in the bus's trace"},
}, "A CAN frame as the bus delivered it, with its 29-bit identifier decoded (ARINC 825)")

TRUTH = _obj("ima.Truth", {
    "t_ns": {"type": "integer"}, "lat_deg": {"type": "number"}, "lon_deg": {"type": "number"},
    "alt_ft": {"type": "number"}, "airspeed_kt": {"type": "number"},
    "heading_deg": {"type": "number"}, "roll_deg": {"type": "number"},
    "pitch_deg": {"type": "number"}, "vs_fpm": {"type": "number"},
}, "The aircraft's true state (the world's truth.jsonl)")

LOCATION_FIX = json.dumps({
    "title": "foxglove.LocationFix", "type": "object",
    "properties": {"timestamp": _TIME, "frame_id": {"type": "string"},
                   "latitude": {"type": "number"}, "longitude": {"type": "number"},
                   "altitude": {"type": "number"},
                   "position_covariance": {"type": "array", "items": {"type": "number"},
                                           "minItems": 9, "maxItems": 9},
                   "position_covariance_type": {"type": "integer"}}}).encode()

_VEC3 = {"type": "object", "properties": {k: {"type": "number"} for k in "xyz"}}
_QUAT = {"type": "object", "properties": {k: {"type": "number"} for k in "xyzw"}}
POSE_IN_FRAME = json.dumps({
    "title": "foxglove.PoseInFrame", "type": "object",
    "properties": {"timestamp": _TIME, "frame_id": {"type": "string"},
                   "pose": {"type": "object", "properties": {"position": _VEC3,
                                                             "orientation": _QUAT}}}}).encode()

FDR = _obj("ima.FdrRecord", {"kind": {"type": "string"}, "t_ns": {"type": "integer"},
                             "frame": {"type": "integer"}},
           "A record of a node's flight data recorder (ima fdr decodes the same)")

VERDICT = _obj("ima.Verdicts", {"verdict": {"type": "string"}},
               "The oracles' verdicts on the run (its summary's judgement)")


def signals(name: str, fields: tuple[str, ...]) -> bytes:
    props = {"t_ns": {"type": "integer"}, "from": {"type": "string"}}
    props.update({f: {"type": "number"} for f in fields})
    return _obj(f"ima.can.{name}", props, f"The signals of CAN message {name} (DBC)")


BUS_EVENT = event("ima.BusEvent", "The CAN bus's events: clients, faults, bus-off, stop")
SKE_EVENT = event("ima.SkeEvent", "A node's SKE trace record (docs/trace-format.md)")
DDS_EVENT = event("ima.DdsEvent", "A DDS agent's trace record (emulated t_ns, wall t_wall_ns)")
WORLD_EVENT = event("ima.WorldEvent", "The world's events: actuators, votes, pilot, faults")
