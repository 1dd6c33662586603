# SPDX-License-Identifier: Apache-2.0
"""Python mirror of nodes/include/xch/proto.h, and a client that plays a node's io partition.

The client is what the tests and tools use in place of the real io partition: same datagrams,
same socket, same rules as nodes/src/xch_client.c.
"""

from __future__ import annotations

import socket
import struct
import time
from dataclasses import dataclass, field, fields

MAGIC = 0x48435849  # "IXCH" as little-endian bytes
VERSION = 1
MAX_NODES = 3

HELLO = 1
WELCOME = 2
INPUTS = 3
AGREED = 4
HEALTH = 5
TELEMETRY = 6
MISSION = 7

IN_GPS = 0x1
IN_AHRS = 0x2
IN_AIR = 0x4

HEALTH_DISAGREE = 0x1
HEALTH_NAV_VALID = 0x2

# (name, struct format) in declaration order; "x" fields are padding. The test compiles the
# header and checks every offset and size against these.
HDR_FIELDS = [("magic", "I"), ("version", "H"), ("type", "H"), ("node", "I"), ("frame", "I"),
              ("t_ns", "q")]
INPUTS_FIELDS = [
    ("valid", "I"), ("wait_mask", "I"),
    ("gps_t_ns", "q"), ("ahrs_t_ns", "q"), ("air_t_ns", "q"),
    ("gps_seq", "I"), ("gps_fix", "I"), ("gps_sats", "I"),
    ("ahrs_seq", "I"), ("ahrs_status", "I"),
    ("air_seq", "I"), ("air_status", "I"),
    ("plan_crc", "I"),
    ("gps", "5d"), ("ahrs", "9d"), ("air", "3d"),
]
HEALTH_FIELDS = [("membership", "I"), ("flags", "I"), ("fcs_mode", "I"), ("failed", "I"),
                 ("hm_events", "Q")]
TELEMETRY_FIELDS = [("fcs_mode", "I"), ("fallback", "I"), ("nav_flags", "I"), ("pad", "I")] + [
    (n, "d") for n in ("lat_deg", "lon_deg", "alt_ft", "ias_kt", "gs_kt", "hdg_deg", "trk_deg",
                       "vs_fpm", "roll_deg", "pitch_deg")] + [("cmd", "4d")]
MISSION_FIELDS = [("mode", "I"), ("lat_mode", "I"), ("vert_mode", "I"), ("pad", "I"),
                  ("hdg_deg", "d"), ("alt_ft", "d"), ("ias_kt", "d"), ("vs_fpm", "d")]


def _fmt(fs) -> str:
    return "<" + "".join(f for _, f in fs)


HDR = struct.Struct(_fmt(HDR_FIELDS))
INPUTS_S = struct.Struct(_fmt(INPUTS_FIELDS))
AGREED_HEAD = struct.Struct("<II")  # present, pad
HEALTH_S = struct.Struct(_fmt(HEALTH_FIELDS))
TELEMETRY_S = struct.Struct(_fmt(TELEMETRY_FIELDS))
MISSION_S = struct.Struct(_fmt(MISSION_FIELDS))
AGREED_SIZE = AGREED_HEAD.size + MAX_NODES * INPUTS_S.size

PAYLOAD_SIZE = {HELLO: 0, WELCOME: 0, INPUTS: INPUTS_S.size, AGREED: AGREED_SIZE,
                HEALTH: HEALTH_S.size, TELEMETRY: TELEMETRY_S.size, MISSION: MISSION_S.size}

assert HDR.size == 24 and INPUTS_S.size == 200


def offsets(fs) -> dict[str, int]:
    """Offset of each field, computed from the packed format (the C layout has no holes)."""
    out, off = {}, 0
    for name, f in fs:
        out[name] = off
        off += struct.calcsize("<" + f)
    return out


@dataclass
class Inputs:
    """struct xch_inputs."""

    valid: int = 0
    wait_mask: int = 0
    gps_t_ns: int = 0
    ahrs_t_ns: int = 0
    air_t_ns: int = 0
    gps_seq: int = 0
    gps_fix: int = 0
    gps_sats: int = 0
    ahrs_seq: int = 0
    ahrs_status: int = 0
    air_seq: int = 0
    air_status: int = 0
    plan_crc: int = 0
    gps: list[float] = field(default_factory=lambda: [0.0] * 5)
    ahrs: list[float] = field(default_factory=lambda: [0.0] * 9)
    air: list[float] = field(default_factory=lambda: [0.0] * 3)

    def pack(self) -> bytes:
        return INPUTS_S.pack(self.valid, self.wait_mask, self.gps_t_ns, self.ahrs_t_ns,
                             self.air_t_ns, self.gps_seq, self.gps_fix, self.gps_sats,
                             self.ahrs_seq, self.ahrs_status, self.air_seq, self.air_status, self.plan_crc,
                             *self.gps, *self.ahrs, *self.air)

    @classmethod
    def unpack(cls, data: bytes) -> Inputs:
        v = INPUTS_S.unpack(data)
        return cls(*v[:13], gps=list(v[13:18]), ahrs=list(v[18:27]), air=list(v[27:30]))


@dataclass
class Agreed:
    """struct xch_agreed with its header's frame."""

    frame: int
    t_ns: int
    present: int
    inputs: list[Inputs]

    def nodes(self) -> list[int]:
        return [k for k in range(1, MAX_NODES + 1) if self.present & (1 << (k - 1))]

    def of(self, node: int) -> Inputs | None:
        return self.inputs[node - 1] if self.present & (1 << (node - 1)) else None


def pack_hdr(type_: int, node: int, frame: int = 0, t_ns: int = 0) -> bytes:
    return HDR.pack(MAGIC, VERSION, type_, node, frame, t_ns)


def pack_health(membership: int = 0, flags: int = 0, fcs_mode: int = 0, failed: int = 0) -> bytes:
    return HEALTH_S.pack(membership, flags, fcs_mode, failed, 0)


def pack_telemetry(**kw) -> bytes:
    vals = []
    for name, f in TELEMETRY_FIELDS:
        if f == "4d":
            vals += list(kw.get(name, [0.0] * 4))
        else:
            vals.append(kw.get(name, 0))
    return TELEMETRY_S.pack(*vals)


def pack_mission(**kw) -> bytes:
    return MISSION_S.pack(*(kw.get(name, 0) for name, _ in MISSION_FIELDS))


def unpack_agreed(data: bytes) -> Agreed:
    if len(data) != HDR.size + AGREED_SIZE:
        raise ValueError(f"AGREED of {len(data)} bytes")
    magic, version, type_, _node, frame, t_ns = HDR.unpack_from(data)
    if magic != MAGIC or version != VERSION or type_ != AGREED:
        raise ValueError("not an AGREED")
    present, _ = AGREED_HEAD.unpack_from(data, HDR.size)
    base = HDR.size + AGREED_HEAD.size
    ins = [Inputs.unpack(data[base + i * INPUTS_S.size: base + (i + 1) * INPUTS_S.size])
           for i in range(MAX_NODES)]
    return Agreed(frame, t_ns, present, ins)


class XchClient:
    """A node's io partition, in Python: HELLO/WELCOME, INPUTS/AGREED, HEALTH, ..."""

    def __init__(self, path: str, node: int, timeout: float = 30.0) -> None:
        self.node = node
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self.sock.settimeout(timeout)
        self.sock.connect(str(path))
        self.sock.send(pack_hdr(HELLO, node))
        data = self.sock.recv(4096)
        if len(data) != HDR.size:
            raise ConnectionError(f"no WELCOME from the agent ({len(data)} bytes)")
        magic, version, type_, wnode, nodes, _ = HDR.unpack(data)
        if (magic, version, type_, wnode) != (MAGIC, VERSION, WELCOME, node):
            raise ConnectionError("the agent did not answer with a WELCOME")
        self.nodes = nodes

    def send_raw(self, data: bytes) -> None:
        self.sock.send(data)

    def send(self, type_: int, frame: int, t_ns: int, payload: bytes) -> None:
        self.sock.send(pack_hdr(type_, self.node, frame, t_ns) + payload)

    def send_inputs(self, frame: int, t_ns: int, inputs: Inputs) -> None:
        self.send(INPUTS, frame, t_ns, inputs.pack())

    def await_agreed(self, frame: int, timeout: float = 10.0) -> Agreed:
        end = time.monotonic() + timeout
        while True:
            left = end - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"no AGREED for frame {frame}")
            self.sock.settimeout(left)
            data = self.sock.recv(4096)
            if not data:
                raise ConnectionError("the agent closed the connection")
            a = unpack_agreed(data)
            if a.frame == frame:
                return a

    def exchange(self, frame: int, t_ns: int, inputs: Inputs, timeout: float = 10.0) -> Agreed:
        self.send_inputs(frame, t_ns, inputs)
        return self.await_agreed(frame, timeout)

    def close(self) -> None:
        self.sock.close()

    def __enter__(self) -> XchClient:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def field_names(cls) -> list[str]:
    return [f.name for f in fields(cls)]
