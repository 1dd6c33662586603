# SPDX-License-Identifier: Apache-2.0
"""The flight summary's judgement: hold segments from a pilot script, errors from truth."""

from __future__ import annotations

import json

import pytest

from ima.flight import summary


def _script(tmp_path, events, settle=30):
    p = tmp_path / "p.yaml"
    p.write_text(json.dumps({
        "start": {"altitude_ft": 3000, "airspeed_kt": 100, "heading_deg": 90},
        "events": events, "evaluate": {"settle_s": settle}}))
    return p


def test_hold_segments_skip_settling_direct_and_link_loss(tmp_path):
    p = _script(tmp_path, [
        {"t": 0, "mode": "AUTOPILOT", "heading_deg": 90, "altitude_ft": 3000, "airspeed_kt": 100},
        {"t": 100, "heading_deg": 180},
        {"t": 200, "c2_link": "down"},
        {"t": 250, "c2_link": "up"},
        {"t": 300, "mode": "DIRECT"},
    ])
    segs = summary.hold_segments(p, 400)
    assert [(s.t0_s, s.t1_s, s.heading_deg) for s in segs] == [
        (30, 100, 90), (130, 200, 180), (280, 300, 180)]


def test_tracking_errors_wrap_heading_and_use_only_segments():
    seg = summary.HoldSegment(10, 20, heading_deg=2.0, altitude_ft=3000, airspeed_kt=100)
    truth = [{"t_ns": int(t * 1e9), "alt_ft": 3000 + d, "airspeed_kt": 100 - d,
              "heading_deg": (2 - d) % 360, "roll_deg": d * 3, "pitch_deg": 0}
             for t, d in ((5, 50.0), (10, 4.0), (15, -3.0), (25, 80.0))]
    e = summary.tracking_errors(truth, [seg])
    assert e["samples_judged"] == 2
    assert e["alt_err_ft_max"] == 4.0 and e["airspeed_err_kt_max"] == 4.0
    assert e["heading_err_deg_max"] == 4.0  # 358° against 002° is 4°, not 356°
    assert e["alt_err_ft_rms"] == pytest.approx(((16 + 9) / 2) ** 0.5, abs=0.01)
    assert e["bank_deg_max"] == 240.0  # over the whole flight, segments or not


def test_wrap180():
    assert summary.wrap180(190) == -170 and summary.wrap180(-190) == 170
