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


def _scripted_bus(path, datagrams):
    """A bus that welcomes one client, then sends it `datagrams` and closes: the records as
    the real bus sends them, one datagram each."""
    import socket

    srv = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    srv.bind(str(path))
    srv.listen(1)

    def serve():
        conn, _ = srv.accept()
        with conn:
            conn.recv(proto.MAX_DATAGRAM)  # the HELLO
            conn.send(proto.pack_welcome(0, 500_000, 10_000_000))
            for d in datagrams:
                conn.send(d)
            conn.recv(proto.MAX_DATAGRAM)  # until the client hangs up
        srv.close()

    t = threading.Thread(target=serve, daemon=True)
    t.start()
    return t


def _frame(id_, t_ns):
    # as delivered: aux = the frame's start on the wire, src = the sender's index
    return proto.pack_rec(proto.MSG_FRAME, id_, t_ns, t_ns - 100, bytes([id_ & 0xFF]),
                          flags=proto.FRAME_EFF, src=3)


def _tick(t_from, t_until):
    return proto.pack_rec(proto.MSG_TICK, 0, t_until, t_from)


def test_frames_of_quanta_not_granted_come_with_the_next_tick(tmp_path):
    """A client granted a later quantum only gets the frames of the quanta before it in
    datagrams of their own, then frames + TICK: every frame, in the bus's order, with that
    TICK; then a STOP after frames alone leaves those frames `unticked`."""
    sock = tmp_path / "bus.sock"
    server = _scripted_bus(sock, [
        _frame(1, 1_000) + _frame(2, 2_000),  # frames alone (a quantum not granted)
        _frame(3, 11_000),                      # frames alone again
        _frame(4, 21_000) + _tick(20_000, 30_000),
        _tick(30_000, 40_000),
        _frame(5, 41_000) + proto.pack_rec(proto.MSG_ERROR, 7, 42_000) + _tick(40_000, 50_000),
        _frame(6, 51_000),
        proto.pack_rec(proto.MSG_STOP, proto.STOP_END, 60_000),
    ])
    c = BusClient(str(sock), "world", LOCK)
    general = []  # the datagrams left to the general path
    push = c._push
    c._push = lambda buf: (general.append(buf[::proto.REC_SIZE]), push(buf))
    try:
        t = c.wait_tick()
        assert (t.t_from, t.t_until) == (20_000, 30_000)
        assert [(f.id, f.t_ns, f.start_ns, f.data, f.src) for f in t.frames] == [
            (k, t_ns, t_ns - 100, bytes([k]), 3)
            for k, t_ns in ((1, 1_000), (2, 2_000), (3, 11_000), (4, 21_000))]
        assert all(f.extended for f in t.frames)
        t = c.wait_tick()
        assert (t.t_from, t.t_until, t.frames) == (30_000, 40_000, [])
        t = c.wait_tick()  # an ERROR among them: the general path, the same frames
        assert (t.t_from, t.t_until, [f.id for f in t.frames]) == (40_000, 50_000, [5])
        assert [e.id for e in c.errors] == [7]
        assert c.wait_tick() is None
        assert (c.stopped, c.stop_t_ns) == (proto.STOP_END, 60_000)
        assert [f.id for f in c.unticked] == [6]
        # frames alone and frames + TICK on the fast path; the ERROR's and the STOP's not
        assert general == [bytes([proto.MSG_FRAME, proto.MSG_ERROR, proto.MSG_TICK]),
                           bytes([proto.MSG_STOP])]
    finally:
        c.close()
        server.join(5)
