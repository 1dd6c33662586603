# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the separation kernel emulator (schedule speed, window switch time, jitter)."""

from __future__ import annotations

from ima.errors import ImaError


def run(frames: int | None = None, json_out: bool = False) -> int:
    """Runs the benchmark over `frames` major frames, prints JSON if `json_out`; exit code."""
    raise ImaError("ima bench ske: not implemented yet")
