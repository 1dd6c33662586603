# SPDX-License-Identifier: Apache-2.0
"""A lean MCAP writer (https://mcap.dev/spec): chunked, zstd-compressed, fully indexed (message
indexes per chunk, chunk indexes, statistics, summary offsets), the data CRC-checked.

The Python `mcap` package's writer costs some 20 µs per message; a 10-minute triplex has
close to a million. This one packs each message header with one struct call into the chunk
being built and keeps its index as two integers, and is read back by the `mcap` package's
reader in the tests (tests/recording/)."""

from __future__ import annotations

import struct
import sys
import zlib
from array import array

MAGIC = b"\x89MCAP0\r\n"
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 1, 2, 3, 4, 5, 6
OP_MESSAGE_INDEX, OP_CHUNK_INDEX, OP_STATISTICS, OP_METADATA = 7, 8, 11, 12
OP_METADATA_INDEX, OP_SUMMARY_OFFSET, OP_DATA_END = 13, 14, 15

_MSG = struct.Struct("<BQHIQQ")  # opcode, record length, channel, sequence, log, publish
_REC = struct.Struct("<BQ")
_LITTLE = sys.byteorder == "little"


def _str(s: str) -> bytes:
    b = s.encode()
    return struct.pack("<I", len(b)) + b


def _map(d: dict) -> bytes:
    body = b"".join(_str(k) + _str(v) for k, v in d.items())
    return struct.pack("<I", len(body)) + body


def _le(a: array) -> bytes:
    """An array of uint64 as MCAP stores integers: little-endian."""
    if _LITTLE:
        return a.tobytes()
    b = array("Q", a)
    b.byteswap()
    return b.tobytes()


def _record(op: int, content: bytes) -> bytes:
    return _REC.pack(op, len(content)) + content


class McapWriter:
    def __init__(self, f, chunk_bytes: int = 1 << 20, level: int = 3,
                 profile: str = "", library: str = "ima-testbed") -> None:
        import zstandard

        self.f = f
        self.pos = 0
        self.crc = 0
        self.chunk_bytes = chunk_bytes
        self.zstd = zstandard.ZstdCompressor(level=level)
        self.schemas: list[bytes] = []
        self.channels: list[bytes] = []
        self.chunk_index: list[bytes] = []
        self.metadata_index: list[bytes] = []
        self.counts: dict[int, int] = {}
        self.n_messages = 0
        self.t_min: int | None = None
        self.t_max = 0
        self._new_chunk()
        self._write(MAGIC)
        self._write(_record(OP_HEADER, _str(profile) + _str(library)))

    # -- output ----------------------------------------------------------------------------
    def _write(self, b: bytes) -> None:
        self.f.write(b)
        self.crc = zlib.crc32(b, self.crc)
        self.pos += len(b)

    def _new_chunk(self) -> None:
        self.buf = bytearray()
        self.index: dict[int, array] = {}  # channel -> [log time, offset, ...] (uint64)
        self.c_min: int | None = None
        self.c_max = 0

    # -- definitions (written into the chunk stream too, so a chunk is readable alone) ------
    def schema(self, sid: int, name: str, encoding: str, data: bytes) -> None:
        rec = _record(OP_SCHEMA, struct.pack("<H", sid) + _str(name) + _str(encoding)
                      + struct.pack("<I", len(data)) + data)
        self.schemas.append(rec)
        self.buf += rec

    def channel(self, cid: int, sid: int, topic: str, encoding: str) -> None:
        rec = _record(OP_CHANNEL, struct.pack("<HH", cid, sid) + _str(topic) + _str(encoding)
                      + _map({}))
        self.channels.append(rec)
        self.counts[cid] = 0
        self.buf += rec

    def metadata(self, name: str, data: dict) -> None:
        self._flush_chunk()
        rec = _record(OP_METADATA, _str(name) + _map(data))
        self.metadata_index.append(_record(OP_METADATA_INDEX, struct.pack(
            "<QQ", self.pos, len(rec)) + _str(name)))
        self._write(rec)

    # -- messages ---------------------------------------------------------------------------
    def message(self, cid: int, seq: int, t: int, data: bytes) -> None:
        buf = self.buf
        idx = self.index.get(cid)
        if idx is None:
            idx = self.index[cid] = array("Q")
        idx.append(t)
        idx.append(len(buf))
        buf += _MSG.pack(OP_MESSAGE, 22 + len(data), cid, seq & 0xFFFFFFFF, t, t)
        buf += data
        if len(buf) >= self.chunk_bytes:
            self._flush_chunk()

    def chunk_used(self) -> int:
        """Bytes of the chunk being built: where the next record goes."""
        return len(self.buf)

    def add_records(self, data, entries: list[tuple[int, array]]) -> None:
        """Message records made elsewhere (recording/fast.py; any bytes-like object, copied
        here), with each channel's index entries (log time, offset in the chunk, as an
        array of uint64; the channels in the order of their first record); the chunk is
        written if full, as after message()."""
        self.buf += data
        for cid, pairs in entries:
            idx = self.index.get(cid)
            if idx is None:
                idx = self.index[cid] = array("Q")
            idx += pairs
        if len(self.buf) >= self.chunk_bytes:
            self._flush_chunk()

    def _flush_chunk(self) -> None:
        if not self.index:
            self._new_chunk()  # definitions only: they are in the summary as well
            return
        for cid, entries in self.index.items():  # the chunk's times and counts
            times = entries[0::2]
            lo, hi = min(times), max(times)
            self.c_min = lo if self.c_min is None else min(self.c_min, lo)
            self.c_max = max(self.c_max, hi)
            self.counts[cid] += len(times)
        raw = self.buf  # a new one follows (_new_chunk): no copy
        comp = self.zstd.compress(raw)
        start = self.pos
        body = (struct.pack("<QQQI", self.c_min, self.c_max, len(raw), zlib.crc32(raw))
                + _str("zstd") + struct.pack("<Q", len(comp)) + comp)
        self._write(_record(OP_CHUNK, body))
        chunk_len = self.pos - start
        offsets = {}
        for cid, entries in self.index.items():
            offsets[cid] = self.pos
            pairs = _le(entries)
            self._write(_record(OP_MESSAGE_INDEX, struct.pack("<HI", cid, len(pairs)) + pairs))
        index_len = self.pos - start - chunk_len
        off_body = b"".join(struct.pack("<HQ", c, o) for c, o in offsets.items())
        self.chunk_index.append(_record(OP_CHUNK_INDEX, struct.pack(
            "<QQQQ", self.c_min, self.c_max, start, chunk_len)
            + struct.pack("<I", len(off_body)) + off_body
            + struct.pack("<Q", index_len) + _str("zstd")
            + struct.pack("<QQ", len(comp), len(raw))))
        n = len(raw) and sum(len(e) // 2 for e in self.index.values())
        self.n_messages += n
        self.t_min = self.c_min if self.t_min is None else min(self.t_min, self.c_min)
        self.t_max = max(self.t_max, self.c_max)
        self._new_chunk()

    # -- the end ------------------------------------------------------------------------------
    def finish(self) -> None:
        self._flush_chunk()
        self._write(_record(OP_DATA_END, struct.pack("<I", self.crc)))
        summary_start = self.pos
        crc_summary = 0
        groups = []
        for op, recs in ((OP_SCHEMA, self.schemas), (OP_CHANNEL, self.channels),
                         (OP_CHUNK_INDEX, self.chunk_index),
                         (OP_METADATA_INDEX, self.metadata_index)):
            if not recs:
                continue
            start = self.pos
            for r in recs:
                self._write(r)
            groups.append((op, start, self.pos - start))
        counts = b"".join(struct.pack("<HQ", c, n) for c, n in self.counts.items())
        stats = _record(OP_STATISTICS, struct.pack(
            "<QHIIII", self.n_messages, len(self.schemas), len(self.channels), 0,
            len(self.metadata_index), len(self.chunk_index))
            + struct.pack("<QQ", self.t_min or 0, self.t_max)
            + struct.pack("<I", len(counts)) + counts)
        start = self.pos
        self._write(stats)
        groups.append((OP_STATISTICS, start, self.pos - start))
        offset_start = self.pos
        for op, start, length in groups:
            self._write(_record(OP_SUMMARY_OFFSET, struct.pack("<BQQ", op, start, length)))
        # the footer's CRC covers the summary from its start through the footer's offsets
        tail = _REC.pack(OP_FOOTER, 20) + struct.pack("<QQ", summary_start, offset_start)
        self.f.flush()
        crc_summary = self._summary_crc(summary_start, tail)
        self.f.write(tail + struct.pack("<I", crc_summary) + MAGIC)

    def _summary_crc(self, summary_start: int, tail: bytes) -> int:
        f = self.f
        here = f.tell()
        f.seek(summary_start)
        data = f.read(here - summary_start)
        f.seek(here)
        return zlib.crc32(tail, zlib.crc32(data))
