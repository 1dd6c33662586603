# SPDX-License-Identifier: Apache-2.0
"""Python mirror of nodes/include/canbus/proto.h: the virtual CAN bus wire protocol."""

from __future__ import annotations

import struct
from typing import NamedTuple

MAGIC = 0x424E4143  # "CANB" as little-endian bytes
VERSION = 1
MAX_RECS = 2048  # records per datagram
NAME_LEN = 32

# Roles a client asks for (hello.roles).
ROLE_CAN = 0x1
ROLE_LOCKSTEP = 0x2
ROLE_OWN = 0x4

WELCOME_REALTIME = 0x1
WELCOME_LISTEN_ONLY = 0x2  # an undeclared client: whatever it sends is refused

# Record types (enum canbus_rec_type).
MSG_FRAME = 1
MSG_TICK = 2
MSG_DONE = 3
MSG_STOP = 4
MSG_ERROR = 5
MSG_FAULT = 6
MSG_PROCESS = 7

# FRAME flags.
FRAME_EFF = 0x1
FRAME_RTR = 0x2

# STOP reasons (enum canbus_stop_reason).
STOP_END = 0
STOP_REQUESTED = 1
STOP_BAD_HELLO = 2
STOP_LATE_JOIN = 3
STOP_FULL = 4
STOP_SIGNAL = 5
STOP_REFUSED = 6

STOP_REASONS = {
    STOP_END: "end of the run",
    STOP_REQUESTED: "a client asked for it",
    STOP_BAD_HELLO: "wrong magic, version, roles or name",
    STOP_LATE_JOIN: "LOCKSTEP client after the start",
    STOP_FULL: "too many clients",
    STOP_SIGNAL: "the bus process was interrupted",
    STOP_REFUSED: "not as the launcher declared it, or its name is taken",
}

# Error state of a CAN controller (ERROR record data[1]).
ERR_ACTIVE = 0
ERR_PASSIVE = 1
ERR_BUS_OFF = 2

# struct canbus_hello: magic, version, roles, name[32], node, reserved
HELLO = struct.Struct("<IHH32sII")
# struct canbus_welcome: magic, version, client, bitrate, flags, quantum_ns, t_ns, end_ns, reserved
WELCOME = struct.Struct("<IHHIIqqqq")
# struct canbus_rec: type, flags, len, src, id, t_ns, aux, data[8]
REC = struct.Struct("<BBBBIqq8s")

HELLO_SIZE = HELLO.size
WELCOME_SIZE = WELCOME.size
REC_SIZE = REC.size
MAX_DATAGRAM = MAX_RECS * REC_SIZE

assert HELLO_SIZE == 48 and WELCOME_SIZE == 48 and REC_SIZE == 32


class Hello(NamedTuple):
    magic: int
    version: int
    roles: int
    name: str
    node: int


class Welcome(NamedTuple):
    magic: int
    version: int
    client: int
    bitrate: int
    flags: int
    quantum_ns: int
    t_ns: int
    end_ns: int


class Rec(NamedTuple):
    type: int
    flags: int
    len: int
    src: int
    id: int
    t_ns: int
    aux: int
    data: bytes  # always 8 bytes as on the wire; the payload is data[:len]


def pack_hello(name: str, roles: int, node: int = 0) -> bytes:
    raw = name.encode()
    if len(raw) >= NAME_LEN:
        raise ValueError(f"client name {name!r} is longer than {NAME_LEN - 1} bytes")
    return HELLO.pack(MAGIC, VERSION, roles, raw, node, 0)


def unpack_hello(buf: bytes) -> Hello:
    magic, version, roles, name, node, _ = HELLO.unpack(buf)
    return Hello(magic, version, roles, name.rstrip(b"\0").decode(errors="replace"), node)


def pack_welcome(client: int, bitrate: int, quantum_ns: int, t_ns: int = 0, end_ns: int = -1,
                 flags: int = 0) -> bytes:
    return WELCOME.pack(MAGIC, VERSION, client, bitrate, flags, quantum_ns, t_ns, end_ns, 0)


def unpack_welcome(buf: bytes) -> Welcome:
    return Welcome(*WELCOME.unpack(buf)[:8])


def pack_rec(type_: int, id_: int = 0, t_ns: int = 0, aux: int = 0, data: bytes = b"",
             flags: int = 0, src: int = 0) -> bytes:
    return REC.pack(type_, flags, len(data), src, id_, t_ns, aux, data)


def pack_frame(id_: int, data: bytes, t_ns: int, extended: bool = True) -> bytes:
    """A FRAME record as a client sends it (t_ns = request time)."""
    return REC.pack(MSG_FRAME, FRAME_EFF if extended else 0, len(data), 0, id_, t_ns, 0, data)


def unpack_recs(buf: bytes) -> list[Rec]:
    """All records of one datagram (its size must be a multiple of REC_SIZE)."""
    if len(buf) % REC_SIZE:
        raise ValueError(f"datagram of {len(buf)} bytes is not a whole number of records")
    return [Rec._make(r) for r in REC.iter_unpack(buf)]


def frame_bits(extended: bool, length: int) -> int:
    """Worst-case bit count of a data frame with `length` data bytes, stuff bits included."""
    g = 54 if extended else 34
    return g + 8 * length + 13 + (g + 8 * length - 1) // 4
