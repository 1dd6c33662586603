# SPDX-License-Identifier: Apache-2.0
"""The recording's C path (python/ima/recording/fast.py, nodes/src/trace_mcap.c) writes the
file the Python writes, byte for byte: for every message of the DBC with random signal values,
for the lines it must hand back (events, cut and garbled lines, odd forms), and with chunks
filling up in the middle of a frame's two messages. Its numbers are orjson's."""

from __future__ import annotations

import json
import math
import random
import struct
import zlib
from pathlib import Path

import orjson
import pytest

from ima.canbus import codec
from ima.recording import fast, write
from ima.recording.follow import Follow
from ima.recording.topics import Topics


@pytest.fixture(autouse=True)
def _library():
    assert fast.library() is not None, f"{fast.library_path()} is not built"


def _record(run_dir: Path, out: Path, c_path: bool, monkeypatch) -> bytes:
    with monkeypatch.context() as m:
        if not c_path:
            m.setattr(fast, "_lib", None)
        write.record(run_dir, output=out, nodes=["node1"])
    return out.read_bytes()


def _can_tx(t: int, msg, data: bytes, frm: str = "world", ext: bool = True) -> str:
    return (f'{{"t_ns":{t},"node":"canbus","src":"canbus","kind":"can_tx","start_ns":{t - 160000},'
            f'"id":{msg.frame_id if msg else 1234},"ext":{"true" if ext else "false"},'
            f'"len":{len(data)},"data":"{data.hex()}","from":"{frm}","client":1}}')


def _random_frame(rng: random.Random, msg) -> bytes:
    # every raw value of every signal, the sign bit included
    return bytes(rng.randrange(256) for _ in range(msg.length))


def _traces(run_dir: Path, rng: random.Random) -> None:
    run_dir.mkdir()
    msgs = list(codec.BY_ID.values())
    can = ['{"t_ns":0,"node":"canbus","src":"canbus","kind":"client_join","name":"world",'
           '"client":1,"roles":["can","lockstep"],"node_id":0}']
    t = 160000
    for _ in range(3000):
        msg = rng.choice(msgs)
        can.append(_can_tx(t, msg, _random_frame(rng, msg)))
        t += 160000
    odd = [
        _can_tx(t, msgs[0], b"").replace('"data":""', '"rtr":true,"data":""'),  # remote frame
        _can_tx(t, None, b"\x01\x02"),                          # an id the DBC does not have
        _can_tx(t, msgs[1], b"\x01\x02", ext=False),            # a standard-format frame
        _can_tx(t, msgs[2], b"\x01\x02\x03").replace('"data":"010203"', '"data":"01020"'),
        _can_tx(t, msgs[2], b"\xab\xcd").replace("abcd", "ABCD"),
        _can_tx(t, msgs[2], b"\xab\xcd").replace("abcd", "ab cd"),
        _can_tx(t, msgs[3], b"\x01" * 8, frm='wo\\"rld'),      # an escape in a string
        _can_tx(t, msgs[3], b"\x01" * 8, frm="wörld"),
        _can_tx(t, msgs[3], b"\x01" * 8).replace('"from":"world",', '"from":null,'),
        _can_tx(t, msgs[3], b"\x01" * 8).replace('"from":"world",', ""),
        _can_tx(t, msgs[3], b"\x01" * 8).replace('"client":1', '"client":1,"duplicate":true'),
        _can_tx(t, msgs[3], b"\x01" * 8).replace('"client":1', '"client":1,"id":7'),
        _can_tx(t, msgs[3], b"\x01" * 8).replace(f'"t_ns":{t}', '"t_ns":-5'),
        _can_tx(t, msgs[3], b"\x01" * 8).replace(f'"t_ns":{t}', f'"t_ns":{t}.0'),
        _can_tx(t, msgs[3], b"\x01" * 8).replace(f'"t_ns":{t}', '"t_ns":0012'),
        _can_tx(t, msgs[3], b"\x01" * 8) + " ",
        _can_tx(t, msgs[3], b"\x01" * 8).replace(",", ", "),
        _can_tx(t, msgs[4], b"\x01" * 8).replace("can_tx", "can_error"),
        _can_tx(t, msgs[4], b"\x01" * 8).replace('"ext":true', '"ext":1'),
        _can_tx(t, msgs[4], b"\x01" * (codec.BY_ID[msgs[4].frame_id].length + 3)),  # too long
        _can_tx(t, msgs[4], b"\x01" * 8).replace('"data":"0101010101010101"', '"data":null'),
        _can_tx(t, msgs[4], b"\x01" * 8).replace(f'"id":{msgs[4].frame_id}', '"id":[1]'),
        _can_tx(t, msgs[4], b"\x01" * 8).replace(f'"id":{msgs[4].frame_id}', '"id":"7"'),
        "not json at all", "[1,2,3]", "{}",
        _can_tx(t, msgs[5], b"\x01" * 8)[:60],                   # cut
    ]
    for k, line in enumerate(odd):  # each among frames the C handles
        can.insert(200 + 97 * k, line)
    can.append(f'{{"t_ns":{t},"node":"canbus","src":"canbus","kind":"bus_stop","reason":"end"}}')
    (run_dir / "can.jsonl").write_text("\n".join(can) + "\n")

    ske = ['{"t_ns":0,"node":"node1","src":"ske","kind":"module_start","windows":[]}']
    for k in range(2000):
        kind = rng.choice(["window_start", "window_end", "window_start", "hm", "mode"])
        ske.append(f'{{"t_ns":{k * 5000000},"node":"node1","src":"ske","kind":"{kind}",'
                   f'"partition":"io","window":1}}')
    for k, line in enumerate(['{"t_ns":+5,"kind":"hm"}', '{"t_ns":1_0,"kind":"hm"}',
                              '{"t_ns":7,"node":"node1"}', '{"t_ns":7,"kind":"hm',
                              '{"t_ns":-7,"kind":"hm"}', '{"t_ns":7}', "garbage"]):
        ske.insert(100 + 211 * k, line)
    (run_dir / "node1.jsonl").write_text("\n".join(ske) + "\n")
    (run_dir / "truth.jsonl").write_text(json.dumps({"t_ns": 0, "lat_deg": 1.0, "lon_deg": 2.0,
                                                     "alt_ft": 3.0}) + "\n")


def test_the_c_writes_what_the_python_writes(tmp_path, monkeypatch):
    run = tmp_path / "run"
    _traces(run, random.Random(17))
    by_python: list[int] = []
    real_can = Topics.can

    def counting_can(self, lines):
        lines = list(lines)
        by_python.append(len(lines))
        real_can(self, lines)

    for chunk_bytes in (1 << 20, 3000, 700):  # chunks that fill up mid-frame too
        monkeypatch.setattr(write, "CHUNK_BYTES", chunk_bytes)
        monkeypatch.setattr(Topics, "can", counting_can)
        by_python.clear()
        c_file = _record(run, tmp_path / f"c{chunk_bytes}.mcap", True, monkeypatch)
        handed_back = sum(by_python)
        monkeypatch.setattr(Topics, "can", real_can)
        py_file = _record(run, tmp_path / f"py{chunk_bytes}.mcap", False, monkeypatch)
        assert c_file == py_file, f"chunks of {chunk_bytes} bytes"
        # the C did the bulk: the Python had the odd lines and each id's first frame
        assert handed_back < 30 + 2 * len(codec.BY_ID), handed_back


def test_numbers_are_written_as_orjson_writes_them():
    rng = random.Random(5)
    values = [0.0, -0.0, 1.0, 0.1, 1e-5, 1.5e-5, 1e-6, 9.99e-6, 1e15, 1e16, 1e17, 2.5e16,
              9999999999999998.0, 1234567890123456.0, 12345678901234567.0, 5e-324,
              2.2250738585072014e-308, 1.7976931348623157e308, 12.340000000000002, -3.5]
    values += [struct.unpack("<d", rng.randbytes(8))[0] for _ in range(20000)]
    for msg in codec.BY_ID.values():  # what signals decode to
        for s in msg.signals:
            for _ in range(200):
                raw = rng.randrange(-(1 << (s.length - 1)), 1 << s.length)
                values.append(float(raw * s.scale + s.offset))
    values += [rng.uniform(-1000, 1000) for _ in range(5000)]
    for x in values:
        if math.isfinite(x):
            assert fast.format_double(x) == orjson.dumps(x), repr(x)
    assert fast.format_double(math.nan) is None
    assert fast.format_double(math.inf) is None


def test_a_trace_is_read_a_block_at_a_time_line_by_line(tmp_path):
    rng = random.Random(3)
    lines = [b"x" * rng.randrange(0, 40) for _ in range(500)]
    for text in (b"\n".join(lines) + b"\n", b"\n".join(lines), b"", b"\n\n"):
        path = tmp_path / "t.jsonl"
        path.write_bytes(text)
        with open(path, "rb") as f:
            expected = [(i, line.rstrip(b"\n")) for i, line in enumerate(f)]
        for block in (1, 7, 64, 1 << 22):
            f = Follow(path)
            got = [line for b in f.blocks(block) for line in b.lines()]
            f.close()
            assert got == expected, (block, len(text))
    assert list(Follow(tmp_path / "missing.jsonl").blocks(5)) == []


def test_more_messages_than_the_c_holds_are_recorded_all_the_same(tmp_path, monkeypatch):
    """A DBC of 300 messages: the C's table holds 256; the frames of the others are the
    Python's, and the file is the same."""
    import dataclasses

    base = codec.BY_ID[min(codec.BY_ID)]
    many = {0x1000 + k: dataclasses.replace(base, name=f"M{k}", frame_id=0x1000 + k)
            for k in range(300)}
    monkeypatch.setattr(codec, "BY_ID", many)
    run = tmp_path / "run"
    run.mkdir()
    rng = random.Random(9)
    lines = [_can_tx(160000 * (k + 1), msg, _random_frame(rng, msg))
             for k, msg in enumerate(list(many.values()) * 2)]
    (run / "can.jsonl").write_text("\n".join(lines) + "\n")
    assert _record(run, tmp_path / "c.mcap", True, monkeypatch) == \
        _record(run, tmp_path / "py.mcap", False, monkeypatch)


def _fdr_record(kind: int, seq: int, t_ns: int, body: bytes, body_len: int | None = None,
                bad_crc: bool = False) -> bytes:
    from ima.fdr import records
    head = records.HEADER.pack(records.MAGIC, records.VERSION, kind, seq,
                               len(body) if body_len is None else body_len, t_ns)
    rec = (head + body).ljust(records.RECORD_SIZE - 4, b"\0")
    crc = zlib.crc32(rec) ^ (1 if bad_crc else 0)
    return rec + struct.pack("<I", crc)


def _fdr_file(rng: random.Random) -> bytes:
    from ima.fdr import records
    specials = [math.nan, math.inf, -math.inf, -0.0, 0.0, 1e-7, 1e16, 123456789.125, -5e-324,
                1.7976931348623157e308]

    def d() -> float:
        return rng.choice(specials) if rng.random() < 0.1 else rng.uniform(-1e4, 1e4)

    def u() -> int:
        return rng.choice([0, 1, 7, 2**32 - 1, rng.randrange(2**32)])

    def frame(k: int) -> bytes:
        nav = records.NAV.pack(rng.randrange(-2**63, 2**63), u(), u(), *[d() for _ in range(12)])
        st = records.STATUS.pack(rng.randrange(2**40), *[u() for _ in range(8)],
                                 *[d() for _ in range(4)])
        mis = records.MISSION.pack(-rng.randrange(2**40), *[u() for _ in range(4)],
                                   *[d() for _ in range(4)])
        return records.FRAME_HEAD.pack(k, rng.randrange(8)) + nav + st + mis

    start = records.START.pack(1, 2, records.RECORD_SIZE, 0, b"node1")
    hm = records.HM.pack(5, b"io", b"rx\xff\xfe", 1, 1, 2, 3, 4, -5, 6, b"overrun \xc3", 0)
    out = [_fdr_record(1, 0, 0, start)]
    for k in range(1, 1500):
        t = rng.choice([k * 50_000_000, 0, -7]) if rng.random() < 0.05 else k * 50_000_000
        out.append(_fdr_record(2, k, t, frame(k)))
    for k, rec in enumerate([_fdr_record(3, 9, 10, hm), _fdr_record(2, 9, 10, frame(9), 100),
                             _fdr_record(2, 9, 10, frame(9), bad_crc=True),
                             b"\0" * records.RECORD_SIZE, _fdr_record(1, 9, 10, start)]):
        out.insert(50 + 137 * k, rec)
    return b"".join(out) + b"FDR1 cut"


def test_the_c_writes_a_flight_data_recording_as_the_python_does(tmp_path, monkeypatch):
    """Frame records by the C, the start and HM records handed back, torn ones (a bad CRC, a
    frame's body too short, zeros) and a cut tail skipped: the same file, whatever the chunk
    size."""
    run = tmp_path / "run"
    _traces(run, random.Random(5))
    (run / "node1.fdr").write_bytes(_fdr_file(random.Random(3)))
    for chunk_bytes in (1 << 20, 5000, 900):
        monkeypatch.setattr(write, "CHUNK_BYTES", chunk_bytes)
        c_file = _record(run, tmp_path / f"c{chunk_bytes}.mcap", True, monkeypatch)
        py_file = _record(run, tmp_path / f"py{chunk_bytes}.mcap", False, monkeypatch)
        assert c_file == py_file, f"chunks of {chunk_bytes} bytes"
    calls = []
    real_fdr = fast.fdr

    def spy(out, topic, data, python):
        def counted(k, seq):
            calls.append(k)
            return python(k, seq)
        return real_fdr(out, topic, data, counted)

    monkeypatch.setattr(fast, "fdr", spy)
    _record(run, tmp_path / "spy.mcap", True, monkeypatch)
    assert len(calls) == 3, calls  # the two start records and the HM record: the rest is the C's


def test_traces_whose_last_line_was_cut_are_recorded_as_the_python_does(tmp_path, monkeypatch):
    """A last line without its newline (its writer killed): the C hands it back at the end of
    the block; the same file, the same line counted as skipped."""
    run = tmp_path / "run"
    _traces(run, random.Random(9))
    whole = write.record(run, output=tmp_path / "whole.mcap", nodes=["node1"])["skipped_lines"]
    for name, keep in (("can.jsonl", -1), ("node1.jsonl", -20)):
        text = (run / name).read_bytes()
        (run / name).write_bytes(text[:keep])
    c_file = _record(run, tmp_path / "c.mcap", True, monkeypatch)
    py_file = _record(run, tmp_path / "py.mcap", False, monkeypatch)
    assert c_file == py_file
    cut = write.record(run, output=tmp_path / "cut.mcap", nodes=["node1"])["skipped_lines"]
    assert cut["node1.jsonl"] == whole["node1.jsonl"] + 1  # the line cut in its middle
