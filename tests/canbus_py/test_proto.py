# SPDX-License-Identifier: Apache-2.0
"""proto.py mirrors nodes/include/canbus/proto.h: every size and constant agrees."""

from __future__ import annotations

import re
from pathlib import Path

from ima.canbus import proto

HEADER = Path(__file__).resolve().parents[2] / "nodes" / "include" / "canbus" / "proto.h"


def _header_constants() -> dict[str, int]:
    text = HEADER.read_text()
    out = {}
    for name, val in re.findall(r"#define\s+CANBUS_(\w+)\s+(0x[0-9a-fA-F]+|\d+)u?\b", text):
        out[name] = int(val, 0)
    for body in re.findall(r"enum\s+\w+\s*\{(.*?)\}", text, re.S):
        body = re.sub(r"/\*.*?\*/", "", body, flags=re.S)
        for name, val in re.findall(r"CANBUS_(\w+)\s*=\s*(\d+)", body):
            out[name] = int(val)
    return out


def test_every_header_constant_is_mirrored():
    consts = _header_constants()
    assert len(consts) >= 25
    for name, val in consts.items():
        py = name[4:] if name.startswith("MSG_") else name
        assert hasattr(proto, name) or hasattr(proto, py), f"proto.py lacks CANBUS_{name}"
        assert getattr(proto, name, getattr(proto, py, None)) == val, name


def test_sizes():
    assert proto.HELLO.size == 48 and proto.HELLO.format == "<IHH32sII"
    assert proto.WELCOME.size == 48
    assert proto.REC.size == 32 and proto.REC.format == "<BBBBIqq8s"
    assert "sizeof(struct canbus_hello) == 48" in HEADER.read_text()
    assert "sizeof(struct canbus_rec) == 32" in HEADER.read_text()


def test_magic_spells_canb():
    assert proto.MAGIC.to_bytes(4, "little") == b"CANB"


def test_roundtrips():
    h = proto.unpack_hello(proto.pack_hello("world", proto.ROLE_CAN | proto.ROLE_LOCKSTEP, 2))
    assert (h.magic, h.version, h.roles, h.name, h.node) == (proto.MAGIC, 1, 3, "world", 2)
    w = proto.unpack_welcome(proto.pack_welcome(3, 1_000_000, 5_000_000, 0, 600 * 10**9))
    assert (w.client, w.bitrate, w.quantum_ns, w.end_ns) == (3, 1_000_000, 5_000_000, 6e11)
    r = proto.unpack_recs(proto.pack_frame(0x1234567, b"\x01\x02", 42))[0]
    assert (r.type, r.flags, r.len, r.id, r.t_ns, r.data[:2]) == (1, 1, 2, 0x1234567, 42, b"\1\2")


def test_frame_bits_matches_the_worst_case_formula():
    # The worst-case stuffed frame length of Davis et al., "Controller Area Network (CAN)
    # schedulability analysis: refuted, revisited and revised" (2007):
    # g + 8s + 13 + floor((g + 8s - 1) / 4), g = 34 (11-bit identifier) or 54 (29-bit)
    assert proto.frame_bits(True, 8) == 54 + 64 + 13 + (54 + 64 - 1) // 4 == 160
    assert proto.frame_bits(False, 0) == 34 + 13 + 33 // 4 == 55
