# SPDX-License-Identifier: Apache-2.0
"""The fast column readers of `ima trace stats` give exactly the frames the frame readers give:
from a recording (scanned chunk by chunk), a python-can log, and where the scan does not
recognise a line, by falling back to reading message by message."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ima.errors import ImaError
from ima.recording import write
from ima.trace import asc, blf, columns, export, source, stats


def _bus_lines(n: int, odd_line: bool = False) -> list[str]:
    head = '{"t_ns":%d,"node":"canbus","src":"canbus","kind":"%s","start_ns":%d'
    out = []
    for k in range(n):
        t = 1_000_000 + k * 997_000
        ext = k % 3 != 0
        cid = (0x0C800000 | (k % 7) << 2 | k % 4) if ext else 0x100 + k % 50
        ext_s = "true" if ext else "false"
        if k % 17 == 5:  # an error frame
            out.append(head % (t, "can_error", t - 100_000)
                       + f',"id":{cid},"ext":{ext_s},"len":8,"from":"node2","tec":8,'
                       '"state":"error_active"}')
        elif k % 23 == 7:  # a remote frame
            out.append(head % (t, "can_tx", t - 50_000)
                       + f',"id":{cid},"ext":{ext_s},"rtr":true,"len":4,"data":"",'
                       '"from":"node1"}')
        else:
            data = bytes((k * 7 + i) & 0xFF for i in range(k % 9))
            out.append(head % (t, "can_tx", t - 100_000)
                       + f',"id":{cid},"ext":{ext_s},"len":{len(data)},'
                       f'"data":"{data.hex()}","from":"node{k % 3 + 1}"}}')
    out.insert(40, '{"t_ns":40000000,"node":"canbus","src":"canbus","kind":"bus_off",'
                   '"name":"node3"}')
    out.insert(80, '{"t_ns":80000000,"node":"canbus","src":"canbus","kind":"bus_on",'
                   '"name":"node3"}')
    if odd_line:  # the same frame, its keys in another order: valid, but not the bus's line
        r = json.loads(out[10])
        out[10] = json.dumps(dict(reversed(list(r.items()))))
    return out


def _same(a: columns.Columns, b: columns.Columns) -> None:
    for name in ("t_ns", "id", "ext", "rtr", "error", "dlen"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.data, b.data)
    assert (a.bus_off, a.duration_ns, a.bitrate) == (b.bus_off, b.duration_ns, b.bitrate)


@pytest.mark.parametrize("odd_line", [False, True])
def test_a_recording_scanned_whole_gives_the_frames_read_one_by_one(tmp_path, odd_line):
    (tmp_path / "can.jsonl").write_text("\n".join(_bus_lines(3000, odd_line)) + "\n")
    write.record(tmp_path)
    (tmp_path / "can.jsonl").unlink()  # the run directory now has only its recording
    fast = columns.load(tmp_path)
    slow = columns.of_trace(source.load(tmp_path))
    _same(fast, slow)
    assert len(fast) == 3000
    assert int(fast.error.sum()) == len([k for k in range(3000) if k % 17 == 5])
    assert fast.bus_off == [{"t_s": 0.04, "client": "node3", "until_s": 0.08}]
    assert stats.compute(fast) == stats.compute(source.load(tmp_path))


def test_the_scan_recognises_the_bus_lines(tmp_path):
    """Without the fallback: every frame is matched by the scan itself."""
    (tmp_path / "can.jsonl").write_text("\n".join(_bus_lines(500)) + "\n")
    write.record(tmp_path)
    assert columns._from_mcap(tmp_path / "run.mcap", None) is not None
    (tmp_path / "can.jsonl").write_text("\n".join(_bus_lines(500, odd_line=True)) + "\n")
    write.record(tmp_path)
    assert columns._from_mcap(tmp_path / "run.mcap", None) is None


@pytest.mark.parametrize("fmt", ["blf", "asc"])
def test_a_python_can_log_gives_the_frames_source_reads(tmp_path, fmt):
    (tmp_path / "can.jsonl").write_text("\n".join(_bus_lines(800)) + "\n")
    log = tmp_path / f"bus.{fmt}"
    export.export(source.load(tmp_path).frames, fmt, log)
    _same(columns.load(log), columns.of_trace(source.load(log)))
    assert stats.compute(columns.load(log)) == stats.compute(source.load(log))


def test_logs_our_readers_do_not_know_are_read_by_python_can(tmp_path):
    (tmp_path / "can.jsonl").write_text("\n".join(_bus_lines(300)) + "\n")
    frames = source.load(tmp_path).frames
    log = tmp_path / "bus.asc"
    export.export(frames, "asc", log)
    text = log.read_text()
    assert asc.read(log) is not None
    dec = tmp_path / "dec.asc"
    dec.write_text(text.replace("base hex", "base dec"))  # hex digits in decimal: unreadable
    assert asc.read(dec) is None
    for load in (columns.load, source.load):
        with pytest.raises(ImaError, match="python-can cannot read it"):
            load(dec)
    odd = {"relative.asc": text.replace("timestamps absolute", "timestamps relative"),
           "attributes.asc": text.replace(" Rx   d 8 ", " Rx   d 8 ", 1).replace(
               "\n", "  Length = 224000 BitCount = 135\n", 7)}
    for name, body in odd.items():
        path = tmp_path / name
        path.write_text(body)
        assert asc.read(path) is None, name
        _same(columns.load(path), columns.of_trace(source.load(path)))
    blf_log = tmp_path / "bus.blf"
    export.export(frames, "blf", blf_log)
    cut = tmp_path / "cut.blf"
    cut.write_bytes(blf_log.read_bytes()[:-40])  # a log whose writer was killed
    assert blf.read(cut) is None
    _same(columns.load(cut), columns.of_trace(source.load(cut)))
