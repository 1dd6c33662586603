# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the Python CAN bus tests: the pure-Python stand-in bus of tests/sim/fakebus.py."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))

from fakebus import FakeBus  # noqa: E402


@pytest.fixture
def sock_path(tmp_path):
    return str(tmp_path / "can.sock")


@pytest.fixture
def fakebus(sock_path):
    """fakebus(**kwargs) -> a started FakeBus on a fresh socket; joined at teardown."""
    buses = []

    def make(**kw):
        b = FakeBus(sock_path, **kw).start()
        buses.append(b)
        return b

    yield make
    for b in buses:
        b.stop_reason = b.stop_reason if b.stop_reason is not None else 1
        b.join(10)
