# SPDX-License-Identifier: Apache-2.0
"""Reading the messages of some topics of an indexed MCAP file fast: the summary's channel and
chunk index records say which chunks hold the topics; only those are decompressed, and their
records are walked with struct. About ten times the `mcap` package's reader on our files.
Falls back to the `mcap` package for a file without a summary (or not zstd/uncompressed)."""

from __future__ import annotations

import struct
from collections.abc import Iterator
from pathlib import Path

from ima.recording.mcapfile import (
    MAGIC,
    OP_CHANNEL,
    OP_CHUNK,
    OP_CHUNK_INDEX,
    OP_FOOTER,
)

_U16, _U32, _U64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<Q")
_REC = struct.Struct("<BQ")
_MSG = struct.Struct("<HIQQ")


def _string(b: bytes, off: int) -> tuple[str, int]:
    n = _U32.unpack_from(b, off)[0]
    return b[off + 4:off + 4 + n].decode(), off + 4 + n


def _summary(f) -> tuple[dict[int, str], list[tuple[int, int, dict[int, int], str]]] | None:
    """({channel id: topic}, [(chunk start, chunk length, {channel: index offset},
    compression)]) from the summary section; None if the file has none."""
    f.seek(0, 2)
    size = f.tell()
    if size < 8 + 29 + 8:
        return None
    f.seek(size - 8 - 29)
    tail = f.read(29 + 8)
    if tail[-8:] != MAGIC or tail[0] != OP_FOOTER:
        return None
    summary_start = _U64.unpack_from(tail, 9)[0]
    if summary_start == 0:
        return None
    f.seek(summary_start)
    body = f.read(size - 8 - 29 - summary_start)
    channels: dict[int, str] = {}
    chunks = []
    off = 0
    while off + 9 <= len(body):
        op, length = _REC.unpack_from(body, off)
        rec = body[off + 9:off + 9 + length]
        off += 9 + length
        if op == OP_CHANNEL:
            cid = _U16.unpack_from(rec, 0)[0]
            topic, _ = _string(rec, 4)
            channels[cid] = topic
        elif op == OP_CHUNK_INDEX:
            start, length_ = struct.unpack_from("<QQ", rec, 16)
            n = _U32.unpack_from(rec, 32)[0]
            idx = {}
            for k in range(n // 10):
                c, o = struct.unpack_from("<HQ", rec, 36 + 10 * k)
                idx[c] = o
            p = 36 + n + 8
            compression, _ = _string(rec, p)
            chunks.append((start, length_, idx, compression))
    return channels, chunks


def _records(f, start: int, length: int, dctx) -> bytes:
    """The records of the chunk at `start`, decompressed."""
    f.seek(start)
    chunk = f.read(length)
    if chunk[0] != OP_CHUNK:
        raise ValueError(f"no chunk at {start}")
    raw_size = _U64.unpack_from(chunk, 9 + 16)[0]
    comp_name, p = _string(chunk, 9 + 28)
    n = _U64.unpack_from(chunk, p)[0]
    data = chunk[p + 8:p + 8 + n]
    return dctx.decompress(data, max_output_size=raw_size) if comp_name else data


def messages(path: Path, topics: list[str]) -> Iterator[tuple[str, int, bytes]]:
    """(topic, log time, data) of the messages of `topics`, chunk by chunk, topic by topic
    within a chunk, each topic's in the order written."""
    with open(path, "rb") as f:
        head = f.read(len(MAGIC))
        if head != MAGIC:
            raise ValueError("not an MCAP file")
        s = _summary(f)
        if s is None or any(c[3] not in ("", "zstd") for c in s[1]):
            yield from _fallback(path, topics)
            return
        channels, chunks = s
        want = {cid: t for cid, t in channels.items() if t in topics}
        import zstandard

        dctx = zstandard.ZstdDecompressor()
        for start, length, idx, _ in chunks:
            if not want.keys() & idx.keys():
                continue
            records = _records(f, start, length, dctx)
            # the chunk's message indexes give each wanted message's offset: no walk over the
            # others (a chunk of the CAN section holds the decoded signals as well)
            for cid in sorted(want.keys() & idx.keys()):
                f.seek(idx[cid])
                head = f.read(9 + 6)
                op, ln = _REC.unpack_from(head, 0)
                n = _U32.unpack_from(head, 11)[0]
                pairs = struct.unpack(f"<{n // 8}Q", f.read(n))
                topic = want[cid]
                for k in range(1, len(pairs), 2):
                    off = pairs[k]
                    ln = _U64.unpack_from(records, off + 1)[0]
                    yield topic, pairs[k - 1], records[off + 9 + 22:off + 9 + ln]


def chunks(path: Path, topics: list[str]) -> Iterator[tuple[bytes, int]] | None:
    """(decompressed records, number of messages of `topics` in them) of every chunk holding
    a message of `topics`, in file order, for a reader that scans a chunk's bytes whole; None
    if the file has no summary to say which (the caller then reads message by message)."""
    with open(path, "rb") as f:
        if f.read(len(MAGIC)) != MAGIC:
            raise ValueError("not an MCAP file")
        s = _summary(f)
    if s is None or any(c[3] not in ("", "zstd") for c in s[1]):
        return None
    channels, index = s
    want = {cid for cid, t in channels.items() if t in topics}
    return _chunk_records(path, [c for c in index if want & c[2].keys()], want)


def _chunk_records(path: Path, index, want: set[int]) -> Iterator[tuple[bytes, int]]:
    import zstandard

    dctx = zstandard.ZstdDecompressor()
    with open(path, "rb") as f:
        for start, length, idx, _ in index:
            count = 0
            for cid in want & idx.keys():  # each message index: (time, offset) pairs
                f.seek(idx[cid] + 9 + 2)
                count += _U32.unpack(f.read(4))[0] // 16
            yield _records(f, start, length, dctx), count


def _fallback(path: Path, topics: list[str]):
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        for _, ch, m in make_reader(f).iter_messages(topics=topics):
            yield ch.topic, m.log_time, m.data
