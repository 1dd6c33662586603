# SPDX-License-Identifier: Apache-2.0
"""The remote pilot station's mission uplink: plan images sent over the C2 link in
MISSION_UPLOAD frames, and the pilot's mission commands in MISSION_CMD frames.

A plan goes out as segment 0 (the image's length and CRC-32) then segments 1..n of six bytes
each, `per_slot` segments every `gap_ms`: a broadcast with a fixed gap and no flow control
(every flight-control node receives the same frames), so not ISO 15765-2. Mission commands
repeat at the pilot-mode rate while the link is up; MC_CNT changes with each new command, so a
node acts on a command once whichever of its copies it hears."""

from __future__ import annotations

import zlib
from dataclasses import dataclass

from ima.canbus.codec import MESSAGES

_UPLOAD = MESSAGES["MISSION_UPLOAD"]
_CMD = MESSAGES["MISSION_CMD"]
SEG_BYTES = 6
MAX_IMAGE = 2504  # RPAS_PLAN_MAX_BYTES (partitions/include/rpas/mission_plan.h): io's bound
COMMANDS = {"engage": 1, "pause": 2, "resume": 3, "direct_to": 4}


@dataclass(frozen=True)
class UplinkParams:
    gap_ms: int = 2      # one slot of segments every gap
    per_slot: int = 2    # segments per slot


def segments(image: bytes, cnt: int) -> list[bytes]:
    """The MISSION_UPLOAD frames' data of one upload (header first)."""
    if not 0 < len(image) <= MAX_IMAGE:
        raise ValueError(f"a plan image of {len(image)} bytes cannot be uplinked")
    crc = zlib.crc32(image) & 0xFFFFFFFF
    out = [_UPLOAD.encode(0, cnt & 0xF, len(image) | (crc << 16))]
    for k in range(0, len(image), SEG_BYTES):
        chunk = image[k:k + SEG_BYTES]
        out.append(_UPLOAD.encode(k // SEG_BYTES + 1, cnt & 0xF, int.from_bytes(chunk, "little")))
    return out


class Uplink:
    """What the station sends of the mission: uploads queued at their times, and commands.

    `uploads`: [(t_ns, image)] in time order. `due`'s `corrupt(t_ns)`: whether the segments
    sent at t_ns go out with a bit flipped (the station's uplink_corrupt fault)."""

    def __init__(self, uploads: list[tuple[int, bytes]], params: UplinkParams = UplinkParams()):
        self.p = params
        self.pending = sorted(uploads, key=lambda u: u[0])
        self.cnt = 0
        self.queue: list[bytes] = []
        self.sent_k = 0
        self.cmd = (0, 0)  # (code, leg)
        self.mc_cnt = 0
        self.events: list[tuple[int, str, dict]] = []  # (t_ns, kind, fields): for world.jsonl

    def command(self, t_ns: int, spec) -> None:
        """A mission command of the script: "engage", "pause", "resume" or {"direct_to": k}."""
        if isinstance(spec, dict):
            self.cmd = (COMMANDS["direct_to"], int(spec["direct_to"]))
        else:
            self.cmd = (COMMANDS[spec], 0)
        self.mc_cnt = (self.mc_cnt + 1) & 0xFF
        self.events.append((t_ns, "mission_cmd", {"cmd": spec if isinstance(spec, str)
                                                   else "direct_to", "leg": self.cmd[1]}))

    def due(self, t_ns: int, link_up: bool, corrupt) -> list[tuple[int, bytes]]:
        """The MISSION_UPLOAD frames of the slot at t_ns (none while the link is down: the
        upload waits, and starts again from its header when the link is back)."""
        while self.pending and self.pending[0][0] <= t_ns:
            _, image = self.pending.pop(0)
            self.cnt = (self.cnt + 1) & 0xF
            self.queue = segments(image, self.cnt)
            self.sent_k = 0
            self.events.append((t_ns, "uplink", {
                "state": "started", "bytes": len(image),
                "crc32": f"0x{zlib.crc32(image) & 0xFFFFFFFF:08x}", "segments": len(self.queue)}))
        if not self.queue:
            return []
        if not link_up:
            self.sent_k = 0  # from the header again when the link is back
            return []
        out = []
        for _ in range(self.p.per_slot):
            if self.sent_k >= len(self.queue):
                break
            data = self.queue[self.sent_k]
            if self.sent_k > 0 and corrupt(t_ns):
                data = data[:2] + bytes([data[2] ^ 0x01]) + data[3:]
                self.events.append((t_ns, "uplink", {"state": "corrupted", "segment": self.sent_k}))
            out.append((_UPLOAD.frame_id, data))
            self.sent_k += 1
        if self.sent_k >= len(self.queue):
            self.events.append((t_ns, "uplink", {"state": "sent"}))
            self.queue = []
        return out

    def command_frame(self) -> tuple[int, bytes]:
        return _CMD.frame_id, _CMD.encode(self.cmd[0], self.cmd[1], self.mc_cnt)
