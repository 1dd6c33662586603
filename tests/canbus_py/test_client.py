# SPDX-License-Identifier: Apache-2.0
"""BusClient against the stand-in lockstep bus: join, quanta, frame delivery, STOP."""

from __future__ import annotations

import threading

import pytest

from ima.canbus import proto
from ima.canbus.client import BusClient, BusError

LOCK = proto.ROLE_CAN | proto.ROLE_LOCKSTEP


def test_two_lockstep_clients_exchange_frames(fakebus, sock_path):
    bus = fakebus(lockstep_clients=2, end_ns=50_000_000)
    got = {}

    def sender():
        c = BusClient(sock_path, "tx", LOCK)
        got["tx_index"] = c.client  # the two threads join in either order
        while (tick := c.wait_tick()) is not None:
            if tick.t_from == 0:
                c.send(0x100, b"\x01\x02\x03", 1_000_000)
                c.send(0x080, b"\x09", 1_000_000)  # lower id wins arbitration
            c.done(tick.t_until)
        got["tx_stop"] = c.stopped
        c.close()

    def receiver():
        c = BusClient(sock_path, "rx", LOCK)
        frames, ticks = [], []
        while (tick := c.wait_tick()) is not None:
            ticks.append((tick.t_from, tick.t_until))
            frames += [(tick.t_from, f) for f in tick.frames]
            c.done(tick.t_until)
        got.update(frames=frames, ticks=ticks, rx_stop=c.stopped)
        c.close()

    th = [threading.Thread(target=f) for f in (sender, receiver)]
    for t in th:
        t.start()
    for t in th:
        t.join(20)
    bus.join(5)
    assert got["ticks"][:2] == [(0, 5_000_000), (5_000_000, 10_000_000)]
    assert len(got["ticks"]) == 10
    assert got["tx_stop"] == got["rx_stop"] == proto.STOP_END
    (t1, f1), (t2, f2) = got["frames"]
    assert (f1.id, f1.data, f2.id, f2.data) == (0x080, b"\x09", 0x100, b"\x01\x02\x03")
    bits1 = proto.frame_bits(True, 1)
    assert (f1.start_ns, f1.t_ns) == (1_000_000, 1_000_000 + bits1 * 1000)
    assert f2.start_ns == f1.t_ns  # waited for the wire
    assert t1 == t2 == 5_000_000  # delivered at the start of the next quantum
    assert f1.extended and f1.src == got["tx_index"]


def test_stop_from_a_client_ends_the_run(fakebus, sock_path):
    bus = fakebus(lockstep_clients=1, end_ns=None)
    c = BusClient(sock_path, "world", LOCK)
    tick = c.wait_tick()
    c.stop()
    assert c.wait_tick() is None and c.stopped == proto.STOP_REQUESTED
    c.close()
    bus.join(5)
    assert tick.t_until == 5_000_000


def test_late_lockstep_client_is_refused(fakebus, sock_path):
    fakebus(lockstep_clients=1, end_ns=None)
    c = BusClient(sock_path, "world", LOCK)
    c.wait_tick()
    with pytest.raises(BusError, match="LOCKSTEP client after the start"):
        BusClient(sock_path, "late", LOCK)
    c.stop()
    c.close()


def test_no_bus_is_a_clear_error(tmp_path):
    with pytest.raises(BusError, match="cannot join the CAN bus"):
        BusClient(str(tmp_path / "nothing.sock"), "x", LOCK, connect_timeout=1)
