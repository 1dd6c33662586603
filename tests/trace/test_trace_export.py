# SPDX-License-Identifier: Apache-2.0
"""ima trace export: every format python-can writes reads back as the same frames."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ima.trace import export, source
from ima.trace.source import Frame

ROOT = Path(__file__).resolve().parents[2]
# the time stamp resolution each format keeps, in ns
RESOLUTION = {"asc": 1_000, "blf": 10_000, "log": 1_000, "trc": 1_000, "csv": 1_000}


def _frames() -> list[Frame]:
    out = []
    for k in range(60):
        t = 1_000_000 + k * 1_234_567
        if k % 10 == 3:
            out.append(Frame(t, 0x123, False, b"", remote=True, dlc=4))
        elif k % 10 == 7:
            out.append(Frame(t, 0, False, b"", error=True))
        else:
            ext = k % 2 == 0
            out.append(Frame(t, (0x1ABCDE00 + k) if ext else (0x100 + k), ext,
                             bytes((k + i) & 0xFF for i in range(k % 9))))
    return out


@pytest.mark.parametrize("fmt", export.FORMATS)
def test_export_then_import_gives_the_same_frames(tmp_path, fmt):
    frames = _frames()
    path = tmp_path / f"bus.{fmt}"
    r = export.export(frames, fmt, path)
    cannot = export.CANNOT.get(fmt, set())
    kept = [f for f in frames if ("error" if f.error else "remote" if f.remote else "data")
            not in cannot]
    assert r["written"] == len(kept)
    assert sum(r["skipped"].values()) == len(frames) - len(kept)
    back = source.load(path).frames
    assert len(back) == len(kept), (fmt, len(back), len(kept))
    t0 = kept[0].t_ns
    for a, b in zip(kept, back, strict=True):
        assert (b.remote, b.error) == (a.remote, a.error), (fmt, a, b)
        if not a.error:  # an error frame has no identifier
            assert (b.id, b.extended) == (a.id, a.extended), (fmt, a, b)
        if not (a.error or a.remote):
            assert b.data == a.data, (fmt, a, b)
        if a.remote and export.REMOTE_DLC[fmt]:
            assert b.dlc == a.dlc, (fmt, a, b)
        assert abs(b.t_ns - (a.t_ns - t0)) <= RESOLUTION[fmt], (fmt, a.t_ns - t0, b.t_ns)
    # one bus, one channel (python-can's candump reader gives error frames none)
    assert len({b.sender for b in back if not b.error}) == 1


def test_the_command_line_reports_what_a_format_cannot_carry(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    recs = [{"t_ns": 1000 * k, "kind": "can_tx", "id": 5, "ext": False, "len": 1, "data": "07",
             "from": "world"} for k in range(1, 4)]
    recs.append({"t_ns": 9000, "kind": "can_error", "id": 0, "ext": False, "len": 0})
    (run / "can.jsonl").write_text("".join(json.dumps(r) + "\n" for r in recs))
    for fmt in export.FORMATS:
        p = subprocess.run([sys.executable, "-m", "ima", "trace", "export", str(run), "--format",
                            fmt, "-o", str(tmp_path / f"out.{fmt}"), "--json"],
                           capture_output=True, text=True, cwd=ROOT)
        assert p.returncode == 0, p.stderr
        r = json.loads(p.stdout)
        assert r["written"] + sum(r["skipped"].values()) == 4, r
        assert r["skipped"] == ({"error": 1} if "error" in export.CANNOT.get(fmt, ()) else {})
    p = subprocess.run([sys.executable, "-m", "ima", "trace", "export", str(run), "--format",
                        "asc", "-o", str(tmp_path)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode != 0 and "is a directory" in p.stderr and "Traceback" not in p.stderr
