# SPDX-License-Identifier: Apache-2.0
"""Decodes a flight data recorder file (partitions/fdr/fdr.h): fixed 320-byte records, each a
header, a body and a CRC-32. A record whose magic, version, kind, length or CRC is wrong is
torn (cut by a crash, or half written when the disk filled) and skipped; a frame number that
jumps is a gap."""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path

RECORD_SIZE = 320
MAGIC = 0x31524446  # "FDR1"
VERSION = 1
KINDS = {1: "start", 2: "frame", 3: "hm"}
HEADER = struct.Struct("<IHHIIq")  # magic, version, kind, seq, body_len, t_ns
BODY_MAX = RECORD_SIZE - HEADER.size - 4

START = struct.Struct("<IIII32s")
NAV_FIELDS = ("t_ns", "flags", "pad", "lat_deg", "lon_deg", "alt_ft", "ias_kt", "gs_kt",
              "trk_deg", "hdg_deg", "vs_fpm", "roll_deg", "pitch_deg", "wind_n_kt", "wind_e_kt")
NAV = struct.Struct("<qII12d")
STATUS_FIELDS = ("t_ns", "mode", "req_mode", "fallback", "nav_flags", "env_flags", "lat_mode",
                 "vert_mode", "pad", "tgt_hdg_deg", "tgt_alt_ft", "tgt_ias_kt", "tgt_vs_fpm")
STATUS = struct.Struct("<q8I4d")
MISSION_FIELDS = ("t_ns", "mode", "lat_mode", "vert_mode", "flags", "hdg_deg", "alt_ft", "ias_kt",
                  "vs_fpm")
MISSION = struct.Struct("<q4I4d")
FRAME_HEAD = struct.Struct("<II")  # frame, valid
HAVE_NAV, HAVE_STATUS, HAVE_MISSION = 1, 2, 4
HM = struct.Struct("<q32s32sIIIIiiI128sI")  # ske_hm_log_t

# The health monitor's names (health_monitor/include/hm/hm.h), as the SKE's trace spells them.
HM_ERRORS = {1: "DEADLINE_MISSED", 2: "APPLICATION_ERROR", 3: "NUMERIC_ERROR",
             4: "ILLEGAL_REQUEST", 5: "STACK_OVERFLOW", 6: "MEMORY_VIOLATION",
             7: "HARDWARE_FAULT", 8: "POWER_FAIL", 9: "WINDOW_OVERRUN", 10: "PARTITION_EXIT"}
HM_LEVELS = {0: "MODULE", 1: "PARTITION", 2: "PROCESS"}
HM_ACTIONS = {0: "IGNORE", 1: "IDLE", 2: "WARM_START", 3: "COLD_START", 4: "SHUTDOWN",
              5: "RESET", 6: "ERROR_HANDLER"}
MODES = ("INIT", "DIRECT", "AUTOPILOT", "MISSION", "CONTINGENCY")
FALLBACKS = ("NONE", "C2_LOST", "MISSION_STALE", "NAV_INVALID", "NO_TARGETS", "SENSOR_LOST")

assert NAV.size == 112 and STATUS.size == 72 and MISSION.size == 56 and HM.size == 232
BODY_MIN = {1: START.size, 2: FRAME_HEAD.size + NAV.size + STATUS.size + MISSION.size,
            3: HM.size}


def _text(raw: bytes) -> str:
    return raw.split(b"\0", 1)[0].decode("utf-8", "replace")


def _named(fields: tuple[str, ...], values: tuple) -> dict:
    d = dict(zip(fields, values, strict=True))
    d.pop("pad", None)
    return d


@dataclass
class Recording:
    path: Path
    starts: list[dict] = field(default_factory=list)
    frames: list[dict] = field(default_factory=list)
    hm: list[dict] = field(default_factory=list)
    torn: list[int] = field(default_factory=list)  # byte offsets of the records skipped
    gaps: list[dict] = field(default_factory=list)
    tail_bytes: int = 0  # a last record cut short

    @property
    def records(self) -> int:
        return len(self.starts) + len(self.frames) + len(self.hm)

    def summary(self) -> dict:
        t = [f["t_ns"] for f in self.frames]
        return {
            "file": str(self.path), "records": self.records, "frames": len(self.frames),
            "hm_events": len(self.hm), "starts": len(self.starts), "torn": len(self.torn),
            "torn_offsets": self.torn[:20], "tail_bytes": self.tail_bytes,
            "gaps": len(self.gaps), "missing_frames": sum(g["missing"] for g in self.gaps),
            "gap_list": self.gaps[:20],
            "t_first_s": t[0] / 1e9 if t else None, "t_last_s": t[-1] / 1e9 if t else None,
        }


def decode(rec: bytes, off: int) -> tuple[str, dict] | None:
    """One record (RECORD_SIZE bytes, at file offset `off`): its kind ("start", "frame",
    "hm") and fields; None if it is torn (a body too short for its kind counts as torn)."""
    magic, version, kind, seq, body_len, t_ns = HEADER.unpack_from(rec)
    crc = struct.unpack_from("<I", rec, RECORD_SIZE - 4)[0]
    if magic != MAGIC or version != VERSION or kind not in KINDS or body_len > BODY_MAX or \
            body_len < BODY_MIN[kind] or zlib.crc32(rec[:RECORD_SIZE - 4]) != crc:
        return None
    body = rec[HEADER.size:HEADER.size + body_len]
    base = {"seq": seq, "t_ns": t_ns, "offset": off}
    if kind == 1:
        cond, mode, size, _, node = START.unpack_from(body)
        return "start", base | {"start_condition": cond, "operating_mode": mode,
                                "node": _text(node), "record_size": size}
    if kind == 2:
        frame, valid = FRAME_HEAD.unpack_from(body)
        o = FRAME_HEAD.size
        nav = _named(NAV_FIELDS, NAV.unpack_from(body, o))
        st = _named(STATUS_FIELDS, STATUS.unpack_from(body, o + NAV.size))
        mis = _named(MISSION_FIELDS, MISSION.unpack_from(body, o + NAV.size + STATUS.size))
        return "frame", base | {"frame": frame,
                                "nav": nav if valid & HAVE_NAV else None,
                                "status": st if valid & HAVE_STATUS else None,
                                "mission": mis if valid & HAVE_MISSION else None}
    (t, part, proc, err, level, action, state, pid, code, n, msg, _) = HM.unpack_from(body)
    return "hm", base | {"hm_t_ns": t, "partition": _text(part), "process": _text(proc),
                         "error": HM_ERRORS.get(err, str(err)),
                         "level": HM_LEVELS.get(level, str(level)),
                         "action": HM_ACTIONS.get(action, str(action)), "state": state,
                         "process_id": pid,
                         "error_code": code, "message": _text(msg[:min(n, 128)])}


def read(path: Path) -> Recording:
    """Every good record of the file, the torn ones' offsets, and the gaps between frames."""
    data = Path(path).read_bytes()
    out = Recording(Path(path))
    whole = len(data) - len(data) % RECORD_SIZE
    out.tail_bytes = len(data) - whole
    lists = {"start": out.starts, "frame": out.frames, "hm": out.hm}
    for off in range(0, whole, RECORD_SIZE):
        got = decode(data[off:off + RECORD_SIZE], off)
        if got is None:
            out.torn.append(off)
        else:
            lists[got[0]].append(got[1])
    last = None
    for f in out.frames:
        if last is not None and f["frame"] > last + 1:
            out.gaps.append({"after_frame": last, "missing": f["frame"] - last - 1,
                             "t_s": f["t_ns"] / 1e9})
        last = f["frame"] if last is None else max(last, f["frame"])
    return out
