# SPDX-License-Identifier: Apache-2.0
"""The lean MCAP writer (python/ima/recording/mcapfile.py), read back record by record with the
`mcap` package: each chunk's message indexes point at that chunk's messages, in the order they
were added, whether a message came one at a time (message()) or in a block made elsewhere
(add_records(), as the recording's C makes them); the chunks' and the file's CRCs hold."""

from __future__ import annotations

import io
import struct
from array import array

import zstandard
from mcap.records import Chunk, MessageIndex
from mcap.stream_reader import StreamReader

from ima.recording.mcapfile import OP_MESSAGE, McapWriter

_HEAD = struct.Struct("<BQHIQQ")  # a Message record's opcode, length, channel, sequence, times


def _block(messages: list[tuple[int, int, bytes]], used: int) -> tuple[bytes, list]:
    """Message records as add_records() takes them (each channel's entries in the order of its
    first record), for a chunk holding `used` bytes already."""
    data = bytearray()
    entries: dict[int, array] = {}
    for cid, t, payload in messages:
        entries.setdefault(cid, array("Q")).extend((t, used + len(data)))
        data += _HEAD.pack(OP_MESSAGE, 22 + len(payload), cid, 0, t, t) + payload
    return bytes(data), list(entries.items())


def _write(chunk_bytes: int) -> tuple[bytes, list[tuple[int, int, bytes]]]:
    f = io.BytesIO()
    w = McapWriter(f, chunk_bytes=chunk_bytes, level=1)
    w.schema(1, "s", "jsonschema", b"{}")
    for cid, topic in ((1, "/a"), (2, "/b"), (3, "/c")):
        w.channel(cid, 1, topic, "json")
    sent = []
    t = 1_000
    for i in range(400):
        if i % 3:
            t += 7
            payload = b'{"i":%d}' % i
            w.message(1 + i % 2, i, t, payload)
            sent.append((1 + i % 2, t, payload))
        else:  # a block of two channels, interleaved, one of them new to the chunk perhaps
            block = [(3, t + 1, b'{"b":%d}' % i), (2, t + 2, b'{"c":%d}' % i),
                     (3, t + 3, b"{}")]
            data, entries = _block(block, w.chunk_used())
            w.add_records(memoryview(data), entries)
            sent += block
            t += 3
    w.finish()
    return f.getvalue(), sent


def test_message_indexes_point_at_their_messages():
    for chunk_bytes in (1 << 20, 700):  # one chunk, and many (some full after a block)
        data, sent = _write(chunk_bytes)
        chunks, got = 0, []
        pending: list[bytes] = []
        for rec in StreamReader(io.BytesIO(data), emit_chunks=True, validate_crcs=True).records:
            if isinstance(rec, Chunk):
                assert rec.compression == "zstd"
                chunks += 1
                pending = [zstandard.ZstdDecompressor().decompress(
                    rec.data, max_output_size=rec.uncompressed_size)]
            elif isinstance(rec, MessageIndex):
                raw = pending[0]
                for log_time, offset in rec.records:
                    op, length, cid, _seq, lt, _pt = _HEAD.unpack_from(raw, offset)
                    assert (op, cid, lt) == (OP_MESSAGE, rec.channel_id, log_time)
                    got.append((offset, chunks, cid, lt, raw[offset + 31:offset + 9 + length]))
        # every message once, each where its index says, in the order written
        got.sort(key=lambda g: (g[1], g[0]))
        assert [(cid, t, p) for _o, _c, cid, t, p in got] == sent
        assert (chunks == 1) if chunk_bytes > len(data) else (chunks > 3)
