# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures of the mission plan tests: a small valid plan as a document, and where the
shipped plans are."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MISSIONS = ROOT / "config" / "missions"

# 47.0 N 8.0 E and points 4 km east (B), 4 km east and 4 km south (C), 1 km south of B (BC).
_DOC = {
    "mission": "small",
    "plan_id": 7,
    "cruise": {"airspeed_kt": 100, "altitude_ft": 3000},
    "waypoints": [
        {"name": "A", "lat_deg": 47.0, "lon_deg": 8.0},
        {"name": "B", "lat_deg": 47.0, "lon_deg": 8.0527462},
        {"name": "C", "lat_deg": 46.9640272, "lon_deg": 8.0527462},
        {"name": "BC", "lat_deg": 46.9910068, "lon_deg": 8.0527462},
    ],
    "runways": [
        {"name": "RWY09", "threshold": {"lat_deg": 46.9640272, "lon_deg": 8.2},
         "elevation_ft": 500, "heading_deg": 90, "length_m": 1500},
    ],
    "legs": [
        {"type": "IF", "fix": "A"},
        {"type": "TF", "fix": "B"},
        {"type": "HM", "fix": "B", "inbound_course_deg": 90, "turn": "right",
         "leg_time_s": 60, "laps": 1},
        {"type": "TF", "fix": "C"},
    ],
    "contingencies": {
        "c2_loss": {"detect_s": 2, "procedure": [{"type": "DF", "fix": "A"}], "resume": True},
        "traffic": {"detect_s": 0.5, "action": "avoid", "offset_deg": 60,
                    "altitude_offset_ft": 500},
    },
}


@pytest.fixture
def doc() -> dict:
    """A small valid plan (a fresh copy): IF A, TF B, HM at B, TF C; two contingencies."""
    return copy.deepcopy(_DOC)
