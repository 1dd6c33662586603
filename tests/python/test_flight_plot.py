# SPDX-License-Identifier: Apache-2.0
"""The flight plot (flight.png) and the small renderer it is drawn with."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

from ima.flight import plot, raster
from ima.flight.summary import HoldSegment


@pytest.mark.parametrize("lo, hi, step, decimals", [
    (0.0, 600.0, 100.0, 0), (2950.0, 4050.0, 200.0, 0), (83.5, 112.0, 5.0, 0),
    (-33.0, 33.0, 10.0, 0), (0.0, 1.0, 0.2, 1), (0.0, 0.12, 0.02, 2), (0.0, 1.7, 0.25, 2),
])
def test_ticks_are_round_steps_within_the_limits(lo, hi, step, decimals):
    ticks, dec = raster.nice_ticks(lo, hi, most=8)
    assert dec == decimals
    assert ticks[0] >= lo - 1e-9 and ticks[-1] <= hi + 1e-9
    assert all(math.isclose(b - a, step) for a, b in zip(ticks, ticks[1:], strict=False))
    assert all(math.isclose(t / step, round(t / step), abs_tol=1e-9) for t in ticks)
    assert 2 <= len(ticks) <= 8


def test_a_degenerate_range_has_one_tick():
    assert raster.nice_ticks(5.0, 5.0) == ([5.0], 0)
    assert raster.label(-0.0, 1) == "0.0" and raster.label(-2.5, 1) == "\u22122.5"


def _truth(n=1200):
    return [{"t_ns": k * 50_000_000, "alt_ft": 3000.0 + k, "airspeed_kt": 100.0,
             "heading_deg": 90.0, "roll_deg": 10.0 * math.sin(k / 50)} for k in range(n)]


def _pixels(path, color, tolerance=40):
    """How many pixels of the image are within `tolerance` of `color` in every channel."""
    img = Image.open(path).convert("RGB")
    assert img.size == (plot.WIDTH, plot.HEIGHT)
    px = np.asarray(img, dtype=np.int16)
    return int((np.abs(px - np.array(color, dtype=np.int16)) <= tolerance).all(axis=2).sum())


EVENT = raster.blend(raster.PURPLE, 0.7)
HOLD = raster.blend(raster.GREEN, 0.08)


def test_the_plot_draws_truth_targets_holds_and_events(tmp_path):
    truth = _truth()
    segs = [HoldSegment(10.0, 50.0, 90.0, 3020.0, 100.0)]
    out = plot.plot_flight(truth, segs, tmp_path / "flight.png", "title",
                           [(30.0, "node3 voted out")])
    assert out == tmp_path / "flight.png"
    assert _pixels(out, raster.BLUE) > 1000  # four truth lines
    assert _pixels(out, raster.RED) > 100  # the targets and the bank limits
    assert _pixels(out, EVENT, 12) > 300  # the event on every panel, its label
    assert _pixels(out, HOLD, 2) > 10_000  # the judged hold


def test_the_plot_without_segments_events_or_values(tmp_path):
    truth = _truth(50)
    truth[10]["alt_ft"] = None  # a value that was not a number: the line breaks there
    for r in truth:
        r["heading_deg"] = None
    out = plot.plot_flight(truth, [], tmp_path / "flight.png", "title")
    assert _pixels(out, HOLD, 2) == 0
    assert _pixels(out, EVENT, 12) == 0
    assert _pixels(out, raster.BLUE) > 100


def test_an_event_after_the_truths_end_widens_the_time_axis(tmp_path):
    """A run cut short (a crash, Ctrl-C) still shows what happened after its last record."""
    truth = _truth(100)  # 0 to 4.95 s
    out = plot.plot_flight(truth, [], tmp_path / "f.png", "t", [(8.0, "node2 stopped")])
    assert _pixels(out, EVENT, 12) > 300  # its line on every panel, and its label
