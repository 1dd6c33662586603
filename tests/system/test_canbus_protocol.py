# SPDX-License-Identifier: Apache-2.0
"""ima-canbus against clients that break its protocol (nodes/include/canbus/proto.h): hellos
it refuses and why, records it rejects one by one, a client sending only garbage, joins past
the start or past --max-clients; the run goes on and ends on a client's STOP."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import threading
import time
from pathlib import Path

from ima.canbus import proto

ROOT = Path(__file__).resolve().parents[2]
BUS = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build")) / "nodes" / "ima-canbus"


def _connect(path: Path) -> socket.socket:
    for _ in range(100):  # the socket file appears just before the bus listens on it
        s = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        s.settimeout(20)
        try:
            s.connect(str(path))
            return s
        except (ConnectionRefusedError, FileNotFoundError):
            s.close()
            time.sleep(0.02)
    raise AssertionError(f"nobody listens at {path}")


def _join(path: Path, name: str, roles: int) -> tuple[socket.socket, bytes]:
    s = _connect(path)
    s.send(proto.pack_hello(name, roles))
    return s, s.recv(proto.MAX_DATAGRAM)


def _refused(answer: bytes) -> int:
    (rec,) = proto.unpack_recs(answer)
    assert rec.type == proto.MSG_STOP, rec
    return rec.id


def _close(bus: subprocess.Popen, clients: list[socket.socket]) -> None:
    for c in clients:
        c.close()
    if bus.poll() is None:
        bus.kill()
        bus.wait()
    bus.stderr.close()


def _next_tick(s: socket.socket) -> int:
    while True:
        for rec in proto.unpack_recs(s.recv(proto.MAX_DATAGRAM)):
            if rec.type == proto.MSG_TICK:
                return rec.t_ns


def test_what_the_bus_refuses_and_rejects(tmp_path):
    sock, trace, stats = tmp_path / "can.sock", tmp_path / "can.jsonl", tmp_path / "can.json"
    bus = subprocess.Popen([str(BUS), "--socket", str(sock), "--lockstep-clients", "1",
                            "--max-clients", "3", "--max-rejects", "8", "--trace", str(trace),
                            "--stats", str(stats), "-q"], stderr=subprocess.PIPE, text=True)
    clients = []
    try:
        for _ in range(400):
            if sock.exists() or bus.poll() is not None:
                break
            time.sleep(0.05)
        # Hellos it refuses: the wrong size, magic or roles.
        s = _connect(sock)
        s.send(b"hi")
        assert _refused(s.recv(proto.MAX_DATAGRAM)) == proto.STOP_BAD_HELLO
        assert s.recv(proto.MAX_DATAGRAM) == b""  # and closed
        s.close()
        s = _connect(sock)
        s.send(proto.HELLO.pack(0xDEAD, proto.VERSION, proto.ROLE_CAN, b"x", 0, 0))
        assert _refused(s.recv(proto.MAX_DATAGRAM)) == proto.STOP_BAD_HELLO
        s.close()
        s, answer = _join(sock, "odd", 0x80)
        assert _refused(answer) == proto.STOP_BAD_HELLO
        s.close()
        # The one lockstep client: the run starts.
        node, answer = _join(sock, "node1", proto.ROLE_CAN | proto.ROLE_LOCKSTEP)
        clients.append(node)
        assert proto.unpack_welcome(answer).client == 0
        t_next = _next_tick(node)
        late, answer = _join(sock, "node2", proto.ROLE_LOCKSTEP)
        assert _refused(answer) == proto.STOP_LATE_JOIN
        late.close()
        logger, answer = _join(sock, "logger", proto.ROLE_OWN)  # receives, may not send
        clients.append(logger)
        noisy, answer = _join(sock, "noisy", proto.ROLE_CAN)
        clients.append(noisy)
        full, answer = _join(sock, "fourth", proto.ROLE_CAN)
        assert _refused(answer) == proto.STOP_FULL
        full.close()
        # Records it rejects, one by one; the clamped frame goes on the wire.
        logger.send(proto.pack_frame(0x100, b"\x01", 0, extended=False))
        node.send(b"".join([
            proto.REC.pack(proto.MSG_FRAME, 0, 9, 0, 0x100, t_next, 0, bytes(8)),
            proto.REC.pack(proto.MSG_FRAME, 0x80, 1, 0, 0x100, t_next, 0, bytes(8)),
            proto.pack_frame(0x800, b"\x02", t_next, extended=False),
            proto.pack_frame(0x123, b"\x03", 0, extended=False),  # before its quantum
            proto.pack_rec(proto.MSG_DONE, t_ns=t_next + 1),
            proto.pack_rec(99),
            proto.pack_rec(proto.MSG_FAULT),
        ]))
        node.send(b"\x00" * 33)
        noisy.send(proto.pack_rec(77) * 9)  # past --max-rejects 8: dropped
        node.send(proto.pack_rec(proto.MSG_DONE, t_ns=t_next))
        _next_tick(node)
        node.send(proto.pack_rec(proto.MSG_STOP, id_=proto.STOP_REQUESTED))
        assert bus.wait(timeout=30) == 0, bus.stderr.read()
    finally:
        _close(bus, clients)
    st = json.loads(stats.read_text())
    assert (st["bad_hellos"], st["late_joins"], st["refused_full"]) == (3, 1, 1), st
    assert st["rejected"] == 1 + 7 + 9 and st["garbage_disconnects"] == 1, st
    lines = [json.loads(line) for line in trace.read_text().splitlines()]
    rejects = [(e.get("name"), e["reason"]) for e in lines if e["kind"] == "reject"]
    assert rejects == [
        ("", "bad_hello"), ("x", "bad_hello"), ("odd", "bad_hello"), ("node2", "late_join"),
        ("fourth", "full"), ("node1", "len"), ("node1", "flags"), ("node1", "id"),
        ("node1", "bad_done"), ("node1", "type"), ("node1", "control_record"),
        ("node1", "size"), ("logger", "frame_without_can_role"),
        *[("noisy", "type")] * 9,
    ], rejects
    left = [(e["name"], e["reason"]) for e in lines if e["kind"] == "client_leave"]
    assert ("noisy", "garbage") in left, left
    assert [e["by"] for e in lines if e["kind"] == "stop_request"] == ["node1"]
    (frame,) = [e for e in lines if e["kind"] == "can_tx"]
    assert (frame["id"], frame["from"], frame["start_ns"]) == (0x123, "node1", 0), frame


def test_a_client_that_stops_reading_is_queued_for_then_dropped(tmp_path):
    """The bus never blocks on a client for long: what a listening client does not read is
    queued, the quantum waits for it at most --send-timeout-ms, then the client is dropped
    and the run goes on. A client that starts reading while the bus waits is served
    everything, in order."""
    sock, trace, stats = tmp_path / "can.sock", tmp_path / "can.jsonl", tmp_path / "can.json"
    bus = subprocess.Popen([str(BUS), "--socket", str(sock), "--lockstep-clients", "1",
                            "--client-buffer", "0", "--send-timeout-ms", "1000",
                            "--trace", str(trace), "--stats", str(stats), "-q"],
                           stderr=subprocess.PIPE, text=True)
    clients = []
    waiting_since = [None]  # when the lockstep client began to wait for its last tick
    late_frames: list[int] = []
    try:
        node, _ = _join(sock, "node1", proto.ROLE_CAN | proto.ROLE_LOCKSTEP)
        clients.append(node)
        slow, _ = _join(sock, "slow", proto.ROLE_CAN)  # never reads
        late, _ = _join(sock, "late", proto.ROLE_CAN)  # reads once the bus waits for it
        clients += [slow, late]
        for c in clients:
            c.settimeout(20)

        def read_late():
            while True:
                t = waiting_since[0]
                if t is not None and time.monotonic() - t > 0.2:
                    break
                time.sleep(0.01)
            while True:
                data = late.recv(proto.MAX_DATAGRAM)
                if not data:
                    return
                late_frames.extend(rec.id for rec in proto.unpack_recs(data)
                                   if rec.type == proto.MSG_FRAME)

        reader = threading.Thread(target=read_late, daemon=True)
        reader.start()
        payload = bytes(range(8))
        t_next = _next_tick(node)
        sent = 0
        waited = False
        while sent < 200000 and not waited:
            node.send(proto.pack_frame(0x100 + sent % 0x400, payload, t_next, extended=False)
                      + proto.pack_rec(proto.MSG_DONE, t_ns=t_next))
            sent += 1
            t0 = waiting_since[0] = time.monotonic()
            t_next = _next_tick(node)
            waiting_since[0] = None
            waited = time.monotonic() - t0 > 0.5  # the bus waited for its slow listeners
        assert waited, "the listening clients never filled their sockets"
        for _ in range(50):  # the run goes on without `slow`
            node.send(proto.pack_rec(proto.MSG_DONE, t_ns=t_next))
            t_next = _next_tick(node)
        node.send(proto.pack_rec(proto.MSG_STOP, id_=proto.STOP_REQUESTED))
        assert bus.wait(timeout=30) == 0, bus.stderr.read()
        reader.join(timeout=20)
        assert not reader.is_alive()
    finally:
        _close(bus, clients)
    st = json.loads(stats.read_text())
    assert st["send_timeouts"] == 1, st
    leaves = [json.loads(line) for line in trace.read_text().splitlines()
              if '"client_leave"' in line]
    assert [(e["name"], e["reason"]) for e in leaves
            if e["name"] in ("slow", "late")] == [("slow", "send_timeout")], leaves
    assert late_frames == [0x100 + k % 0x400 for k in range(sent)]


def test_many_datagrams_in_one_quantum_are_all_read_in_order(tmp_path):
    """The bus reads a client's datagrams several at a time: 21 of them waiting at once (sent
    while the bus is stopped; a bad one among them, rejected alone), then the DONE, put 20
    frames on the wire in the order sent, all in that quantum; a client joining later is still
    accepted."""
    sock, trace, stats = tmp_path / "can.sock", tmp_path / "can.jsonl", tmp_path / "can.json"
    bus = subprocess.Popen([str(BUS), "--socket", str(sock), "--lockstep-clients", "1",
                            "--trace", str(trace), "--stats", str(stats), "-q"],
                           stderr=subprocess.PIPE, text=True)
    clients = []
    try:
        node, _ = _join(sock, "node1", proto.ROLE_CAN | proto.ROLE_LOCKSTEP)
        clients.append(node)
        chatty, _ = _join(sock, "chatty", proto.ROLE_CAN)
        clients.append(chatty)
        t_next = _next_tick(node)
        bus.send_signal(signal.SIGSTOP)  # all of them waiting when the bus looks
        try:
            for k in range(20):
                chatty.send(proto.pack_frame(0x200 + k, bytes([k]), t_next, extended=False))
                if k == 9:
                    chatty.send(b"\x00" * 33)  # not a whole number of records
            node.send(proto.pack_rec(proto.MSG_DONE, t_ns=t_next))
        finally:
            bus.send_signal(signal.SIGCONT)
        t_next = _next_tick(node)
        later, answer = _join(sock, "later", proto.ROLE_CAN)
        clients.append(later)
        assert len(answer) == proto.WELCOME_SIZE
        for _ in range(10):  # time enough for the 20 frames on the wire
            node.send(proto.pack_rec(proto.MSG_DONE, t_ns=t_next))
            t_next = _next_tick(node)
        node.send(proto.pack_rec(proto.MSG_STOP, id_=proto.STOP_REQUESTED))
        assert bus.wait(timeout=30) == 0, bus.stderr.read()
    finally:
        _close(bus, clients)
    lines = [json.loads(line) for line in trace.read_text().splitlines()]
    sent = [e["id"] for e in lines if e["kind"] == "can_tx" and e["from"] == "chatty"]
    assert sent == [0x200 + k for k in range(20)], sent
    # all read in the quantum they were sent in: on the wire back to back from its start
    wire = [(e["start_ns"], e["t_ns"]) for e in lines if e["kind"] == "can_tx"]
    assert [a for a, _ in wire] == [0] + [b for _, b in wire[:-1]], wire
    rejects = [(e.get("name"), e["reason"]) for e in lines if e["kind"] == "reject"]
    assert rejects == [("chatty", "size")], rejects
    assert "later" in [e.get("name") for e in lines if e["kind"] == "client_join"]
