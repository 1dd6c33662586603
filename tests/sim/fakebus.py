# SPDX-License-Identifier: Apache-2.0
"""A tiny pure-Python stand-in of the lockstep CAN bus (ima-canbus), for unit tests of the world.

It follows nodes/include/canbus/proto.h closely enough for one component's tests: hello and
welcome, quanta with TICK/DONE, frames delivered at the start of the first quantum after their
end on the wire, arbitration by lowest identifier, worst-case-stuffed frame lengths, STOP at
the end or on request. It does not model error frames or faults. The real bus is C
(nodes/); integration with it is tested elsewhere.
"""

from __future__ import annotations

import os
import selectors
import socket
import threading
import time
from dataclasses import dataclass, field

from ima.canbus import proto

INJECTOR_SRC = 250  # client index shown for frames the test injects


@dataclass
class _Client:
    sock: socket.socket
    index: int
    name: str
    roles: int
    done_t: int = -1
    delivered: int = 0  # how many trace entries it has been given


@dataclass(order=True)
class _Pending:
    t_req: int
    id: int
    src: int
    seq: int
    flags: int = field(compare=False)
    data: bytes = field(compare=False)


@dataclass
class TraceEntry:
    end_ns: int
    start_ns: int
    src: int
    id: int
    flags: int
    data: bytes


class FakeBus:
    """Run with `start()`; `join()` waits for the end. `injector(t_from, t_until)` may return
    frames [(t_req_ns, id, data)] put on the bus by a virtual client (index INJECTOR_SRC)."""

    def __init__(self, path: str, lockstep_clients: int = 1, quantum_ns: int = 5_000_000,
                 end_ns: int | None = None, bitrate: int = 1_000_000, injector=None,
                 realtime: bool = False, client_timeout_s: float = 60.0) -> None:
        self.path = str(path)
        self.lockstep_needed = lockstep_clients
        self.q = quantum_ns
        self.end_ns = end_ns
        self.bitrate = bitrate
        self.injector = injector
        self.realtime = realtime
        self.client_timeout_s = client_timeout_s
        self.trace: list[TraceEntry] = []
        self.t_ns = 0
        self.stop_reason: int | None = None
        self.error: BaseException | None = None
        self.clients: list[_Client] = []
        self._pending: list[_Pending] = []
        self._seq = 0
        self._busy_until = 0
        self._started = False
        if os.path.exists(self.path):
            os.unlink(self.path)
        self._lsock = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self._lsock.bind(self.path)
        self._lsock.listen(16)
        self._sel = selectors.DefaultSelector()
        self._sel.register(self._lsock, selectors.EVENT_READ, None)
        self._thread = threading.Thread(target=self._main, name="fakebus", daemon=True)

    # -- public --------------------------------------------------------------------------
    def start(self) -> FakeBus:
        self._thread.start()
        return self

    def join(self, timeout: float | None = None) -> None:
        self._thread.join(timeout)
        if self.error:
            raise self.error

    def frames(self, id_: int | None = None) -> list[TraceEntry]:
        return [e for e in self.trace if id_ is None or e.id == id_]

    # -- internals -----------------------------------------------------------------------
    def _main(self) -> None:
        try:
            self._run()
        except BaseException as e:  # reported by join()
            self.error = e
        finally:
            for c in self.clients:
                c.sock.close()
            self._lsock.close()

    def _accept(self) -> None:
        s, _ = self._lsock.accept()
        s.settimeout(5.0)
        buf = s.recv(proto.MAX_DATAGRAM)
        s.settimeout(None)
        ok = len(buf) == proto.HELLO_SIZE
        hello = proto.unpack_hello(buf) if ok else None
        if not ok or hello.magic != proto.MAGIC or hello.version != proto.VERSION:
            s.send(proto.pack_rec(proto.MSG_STOP, proto.STOP_BAD_HELLO))
            s.close()
            return
        if hello.roles & proto.ROLE_LOCKSTEP and self._started:
            s.send(proto.pack_rec(proto.MSG_STOP, proto.STOP_LATE_JOIN))
            s.close()
            return
        c = _Client(s, len(self.clients), hello.name, hello.roles, delivered=len(self.trace))
        self.clients.append(c)
        s.send(proto.pack_welcome(c.index, self.bitrate, self.q, self.t_ns,
                                  -1 if self.end_ns is None else self.end_ns))
        self._sel.register(s, selectors.EVENT_READ, c)

    def _lockstep(self) -> list[_Client]:
        return [c for c in self.clients if c.roles & proto.ROLE_LOCKSTEP and c.sock.fileno() >= 0]

    def _drop(self, c: _Client) -> None:
        self._sel.unregister(c.sock)
        c.sock.close()

    def _read_client(self, c: _Client, t_from: int) -> None:
        try:
            buf = c.sock.recv(proto.MAX_DATAGRAM)
        except OSError:
            buf = b""
        if not buf:
            self._drop(c)
            return
        for r in proto.unpack_recs(buf):
            if r.type == proto.MSG_FRAME:
                t_req = r.t_ns if c.roles & proto.ROLE_LOCKSTEP else t_from
                self._pending.append(_Pending(max(t_req, t_from), r.id, c.index, self._seq,
                                              r.flags, r.data[:r.len]))
                self._seq += 1
            elif r.type == proto.MSG_DONE:
                c.done_t = r.t_ns
            elif r.type == proto.MSG_STOP:
                self.stop_reason = proto.STOP_REQUESTED

    def _poll(self, timeout: float, t_from: int) -> None:
        for key, _ in self._sel.select(timeout):
            if key.data is None:
                self._accept()
            elif key.data.sock.fileno() >= 0:
                self._read_client(key.data, t_from)

    def _send(self, c: _Client, data: bytes) -> None:
        try:
            c.sock.send(data)
        except OSError:
            if c.sock.fileno() >= 0:
                self._drop(c)

    def _run(self) -> None:
        deadline = time.monotonic() + self.client_timeout_s
        while len(self._lockstep()) < self.lockstep_needed:
            if time.monotonic() > deadline:
                raise TimeoutError("lockstep clients did not join")
            self._poll(0.1, 0)
        self._started = True
        epoch = time.monotonic()
        T = 0
        while True:
            self.t_ns = T
            if self.stop_reason is None and self.end_ns is not None and T >= self.end_ns:
                self.stop_reason = proto.STOP_END
            if self.stop_reason is not None:
                stop = proto.pack_rec(proto.MSG_STOP, self.stop_reason)
                for c in self.clients:
                    if c.sock.fileno() >= 0:
                        self._send(c, stop)
                return
            if self.realtime:
                delay = epoch + T / 1e9 - time.monotonic()
                if delay > 0:
                    self._poll(delay, T)
            Tend = T + self.q
            # a. frames that ended by T, then TICK
            for c in list(self.clients):
                if c.sock.fileno() < 0 or not c.roles & proto.ROLE_CAN:
                    continue
                recs = [proto.REC.pack(proto.MSG_FRAME, e.flags, len(e.data), e.src, e.id,
                                       e.end_ns, e.start_ns, e.data)
                        for e in self.trace[c.delivered:]
                        if e.end_ns <= T and (e.src != c.index or c.roles & proto.ROLE_OWN)]
                while c.delivered < len(self.trace) and self.trace[c.delivered].end_ns <= T:
                    c.delivered += 1
                for i in range(0, len(recs), proto.MAX_RECS):
                    self._send(c, b"".join(recs[i:i + proto.MAX_RECS]))
            tick = proto.pack_rec(proto.MSG_TICK, 0, Tend, T)
            for c in self._lockstep():
                self._send(c, tick)
            # b. every lockstep client answers DONE(Tend)
            deadline = time.monotonic() + self.client_timeout_s
            while any(c.done_t < Tend for c in self._lockstep()) and self.stop_reason is None:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"no DONE({Tend}) from a lockstep client")
                self._poll(0.5, T)
            # c. read every socket dry, inject, simulate the wire through [T, Tend)
            self._poll(0.0, T)
            if self.injector is not None:
                for t_req, id_, data in self.injector(T, Tend):
                    self._pending.append(_Pending(max(t_req, T), id_, INJECTOR_SRC, self._seq,
                                                  proto.FRAME_EFF, bytes(data)))
                    self._seq += 1
            self._wire(T, Tend)
            T = Tend

    def _wire(self, T: int, Tend: int) -> None:
        t = max(T, self._busy_until)
        pending = self._pending
        while t < Tend and pending:
            ready = [p for p in pending if p.t_req <= t]
            if not ready:
                t = min(p.t_req for p in pending)
                continue
            win = min(ready, key=lambda p: (p.id, p.src, p.seq))
            pending.remove(win)
            bits = proto.frame_bits(bool(win.flags & proto.FRAME_EFF), len(win.data))
            end = t + bits * 1_000_000_000 // self.bitrate
            self.trace.append(TraceEntry(end, t, win.src, win.id, win.flags, win.data))
            self._busy_until = t = end


class LoopbackBus:
    """An in-process stand-in of BusClient for unit tests without sockets: it grants quanta one
    after the other up to `end_ns` and delivers the frames `injector(t_from, t_until)` returns
    [(t_ns, id, data)] at the start of the next quantum (zero wire time). Frames the world sends
    are kept in `sent` as (t_ns, id, data)."""

    def __init__(self, end_ns: int, quantum_ns: int = 5_000_000, injector=None) -> None:
        from ima.canbus.client import Frame

        self._Frame = Frame
        self.end_ns = end_ns
        self.q = quantum_ns
        self.injector = injector
        self.sent: list[tuple[int, int, bytes]] = []
        self.stopped: int | None = None
        self._t = 0
        self._due: list = []

    def send(self, id_: int, data: bytes, t_ns: int = 0, extended: bool = True) -> None:
        self.sent.append((t_ns, id_, bytes(data)))

    def wait_tick(self, timeout=None):
        from ima.canbus.client import Tick

        if self.stopped is not None:
            return None
        T = self._t
        if T >= self.end_ns:
            self.stopped = proto.STOP_END
            return None
        frames, self._due = self._due, []
        if self.injector is not None:
            self._due = [self._Frame(i, bytes(d), max(t, T + self.q), T + self.q, INJECTOR_SRC,
                                     proto.FRAME_EFF) for t, i, d in self.injector(T, T + self.q)]
        return Tick(T, T + self.q, frames)

    def done(self, t_ns: int) -> None:
        self._t = t_ns

    def stop(self, reason: int = proto.STOP_REQUESTED) -> None:
        self.stopped = reason

    def close(self) -> None:
        pass
