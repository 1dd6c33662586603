# SPDX-License-Identifier: Apache-2.0
"""ima trace stats: exact frame lengths, bus load, periods against the DBC, gaps, logs."""

from __future__ import annotations

import json
import random
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ima.errors import ImaError
from ima.trace import bits, source, stats

ROOT = Path(__file__).resolve().parents[2]
AHRS_ATT = 152044320  # 29-bit, 20 ms in the DBC
PILOT_STICK = 146278360  # 29-bit, 50 ms


def test_a_frame_of_zeros_is_stuffed_every_five_bits():
    # 11-bit identifier 0, no data: 34 zero bits from SOF to the CRC (the CRC of zeros is 0),
    # a stuff bit after each five: 6; then 13 bits of delimiters, EOF and intermission
    assert bits.unstuffed(0, False, b"") == [0] * 34
    assert bits.stuff_count([0] * 34) == 6
    assert bits.frame_bits(0, False, b"") == 34 + 6 + 13


def test_a_stuff_bit_starts_the_next_run():
    # 00000 (stuff 1) 1111: the stuff bit and four ones make five: stuffed again
    assert bits.stuff_count([0] * 5 + [1] * 4) == 2
    assert bits.stuff_count([0] * 4 + [1] * 4) == 0
    assert bits.stuff_count([0] * 5 + [1] * 3 + [0]) == 1


def test_the_crc_makes_the_frame_divisible_by_the_polynomial():
    r = random.Random(7)
    for _ in range(200):
        data = bytes(r.getrandbits(8) for _ in range(r.randint(0, 8)))
        ext = r.random() < 0.5
        frame = bits.unstuffed(r.getrandbits(29 if ext else 11), ext, data)
        assert bits.crc15(frame) == 0  # message and its CRC: remainder zero


def test_exact_lengths_lie_between_the_unstuffed_and_the_worst_case():
    r = random.Random(11)
    for _ in range(2000):
        n = r.randint(0, 8)
        ext = r.random() < 0.5
        data = bytes(r.choice((0, 0xFF, r.getrandbits(8))) for _ in range(n))
        exact = bits.frame_bits(r.getrandbits(29 if ext else 11), ext, data)
        bare = (54 if ext else 34) + 8 * n + 13
        assert bare <= exact <= bits.worst_case_bits(ext, n)
    assert bits.worst_case_bits(False, 8) == 135 and bits.worst_case_bits(True, 8) == 160


def _bus_trace(path: Path, frames: list[tuple[int, int, str]], extra: list[dict] = ()) -> None:
    lines = [{"t_ns": t, "node": "canbus", "src": "canbus", "kind": "can_tx",
              "start_ns": t - 160_000, "id": i, "ext": True, "len": len(d) // 2, "data": d,
              "from": "world", "client": 3} for t, i, d in frames]
    lines += list(extra)
    lines.sort(key=lambda x: x["t_ns"])
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))


def test_periods_gaps_and_deadline_misses_against_the_dbc(tmp_path):
    # AHRS_ATT every 20 ms, one frame missing (a 40 ms interval), one 23 ms late
    times = [k * 20_000_000 for k in range(50) if k != 10]
    times[30] += 3_000_000
    frames = [(t, AHRS_ATT, "0011223344556677") for t in times]
    frames += [(k * 50_000_000 + 1_000_000, PILOT_STICK, "00") for k in range(20)]
    _bus_trace(tmp_path / "can.jsonl", frames, [
        {"t_ns": 500_000_000, "kind": "bus_off", "name": "node2/io"},
        {"t_ns": 700_000_000, "kind": "bus_on", "name": "node2/io"},
        {"t_ns": 800_000_000, "kind": "can_error", "id": 5, "ext": False, "len": 0}])
    r = stats.compute(source.load(tmp_path), stats.load_dbc(None), window_s=0.5,
                      bitrate=500_000)
    att = next(i for i in r["ids"] if i["name"] == "AHRS_ATT")
    assert att["count"] == 49 and att["cycle_ms"] == 20
    assert att["gaps"] == 1
    assert att["deadline_misses"] == 2  # the gap (40 ms) and the late frame (23 ms)
    assert att["period_ms_p50"] == 20.0 and att["period_ms_max"] == 40.0
    stick = next(i for i in r["ids"] if i["name"] == "PILOT_STICK")
    assert stick["gaps"] == 0 and stick["deadline_misses"] == 0 and stick["count"] == 20
    assert r["frames"] == 69 and r["error_frames"] == 1
    assert r["bus_off"] == [{"t_s": 0.5, "client": "node2/io", "until_s": 0.7}]
    # the load of each window: the exact bits of its frames over 0.5 s at 500 kbit/s
    first = [f for f in source.load(tmp_path).frames if f.t_ns < 500_000_000 and not f.error]
    want = sum(bits.frame_bits(f.id, f.extended, f.data) for f in first) / 250_000
    assert r["windows"][0]["load"] == round(want, 4)
    assert r["windows"][0]["load"] < r["windows"][0]["load_worst_case"]


def test_a_python_can_log_is_analysed(tmp_path):
    import can

    log = tmp_path / "bus.asc"
    with can.ASCWriter(str(log)) as w:
        for k in range(40):
            w.on_message_received(can.Message(timestamp=100.0 + k * 0.02,
                                              arbitration_id=AHRS_ATT, is_extended_id=True,
                                              data=bytes(8)))
    r = stats.compute(source.load(log), stats.load_dbc(None))
    assert r["frames"] == 40 and r["ids"][0]["name"] == "AHRS_ATT"
    assert r["ids"][0]["period_ms_p50"] == pytest.approx(20.0, abs=0.01)
    assert r["ids"][0]["gaps"] == 0


def test_the_command_line(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    _bus_trace(run / "can.jsonl", [(k * 20_000_000, AHRS_ATT, "00" * 8) for k in range(100)])
    (run / "launch.json").write_text(json.dumps({"commands": {"canbus": [
        "ima-canbus", "--bitrate", "250000"]}}))
    png = tmp_path / "load.png"
    p = subprocess.run([sys.executable, "-m", "ima", "trace", "stats", str(run), "--json",
                        "--plot", str(png)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["bitrate"] == 250_000 and out["frames"] == 100 and png.stat().st_size > 1000
    assert {"frames", "bus_load", "ids"} <= set(out)
    assert {"id", "name", "count", "period_ms_p50", "period_ms_p99", "gaps"} <= set(out["ids"][0])
    text = subprocess.run([sys.executable, "-m", "ima", "trace", "stats", str(run)],
                          capture_output=True, text=True, cwd=ROOT)
    assert text.returncode == 0 and "AHRS_ATT" in text.stdout and "250,000" in text.stdout
    for bad, why in (([str(tmp_path / "nope")], "no such file"),
                     ([str(tmp_path)], "no can.jsonl"),
                     ([str(run), "--window", "nan"], "--window")):
        p = subprocess.run([sys.executable, "-m", "ima", "trace", "stats", *bad],
                           capture_output=True, text=True, cwd=ROOT)
        assert p.returncode != 0 and why in p.stderr and "Traceback" not in p.stderr, p.stderr


def test_an_unreadable_log_is_an_error(tmp_path):
    bad = tmp_path / "x.blf"
    bad.write_bytes(b"not a blf")
    with pytest.raises(ImaError):
        source.load(bad)


def test_many_frames_at_once_have_the_lengths_of_each_alone():
    r = random.Random(5)
    frames = []
    for _ in range(3000):
        ext, remote = r.random() < 0.5, r.random() < 0.1
        n = r.randint(0, 8)
        data = b"" if remote else bytes(r.choice((0, 0xFF, 0x0F, 0xF0, r.getrandbits(8)))
                                        for _ in range(n))
        frames.append((r.choice((0, (1 << (29 if ext else 11)) - 1, r.getrandbits(
            29 if ext else 11))), ext, remote, data))
    data8 = np.zeros((len(frames), 8), dtype=np.uint8)
    for k, f in enumerate(frames):
        data8[k, :len(f[3])] = list(f[3])
    many = bits.frame_bits_columns([f[0] for f in frames], [f[1] for f in frames],
                                   [f[2] for f in frames], [len(f[3]) for f in frames], data8)
    assert list(many) == [bits.frame_bits(i, e, d, rt) for i, e, rt, d in frames]
