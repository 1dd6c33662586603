# SPDX-License-Identifier: Apache-2.0
"""A client of the virtual CAN bus (ima-canbus): connect, exchange frames, follow the lockstep."""

from __future__ import annotations

import select
import socket
from typing import NamedTuple

from ima.errors import ImaError

from . import proto

_REC = proto.REC
_REC_SIZE = proto.REC_SIZE
_pack = _REC.pack
_unpack = _REC.unpack
_iter_unpack = _REC.iter_unpack
_MSG_DONE = proto.MSG_DONE
_MSG_FRAME = proto.MSG_FRAME
_MSG_TICK = proto.MSG_TICK
_MSG_STOP = proto.MSG_STOP
_MSG_ERROR = proto.MSG_ERROR
_FRAME_EFF = proto.FRAME_EFF


class BusError(ImaError):
    """The bus refused us, closed the connection or sent something we cannot read."""


class Frame(NamedTuple):
    """A frame as the bus delivered it: `t_ns` = end of frame on the wire, `start_ns` = start."""

    id: int
    data: bytes
    t_ns: int
    start_ns: int
    src: int
    flags: int

    @property
    def extended(self) -> bool:
        return bool(self.flags & _FRAME_EFF)


class Tick(NamedTuple):
    t_from: int  # start of the granted quantum
    t_until: int  # the time granted (exclusive)
    frames: list  # list[Frame] delivered with this TICK, in bus order


class BusClient:
    """One SOCK_SEQPACKET connection to the bus, as in nodes/include/canbus/proto.h.

    Frames queued with `send()` go out in one datagram with the next `done()` (or `flush()`),
    so a lockstep client costs the bus one datagram per quantum. `stopped` holds the STOP
    reason once the bus has ended the run (or None), `stop_t_ns` the instant it ended it at,
    and `unticked` the frames delivered after the last TICK, before the STOP (a bus that
    closes the connection without a STOP leaves `stop_t_ns` None: those frames are not told).
    """

    def __init__(self, path: str, name: str, roles: int, node: int = 0,
                 connect_timeout: float = 10.0) -> None:
        self.path = str(path)
        self.name = name
        self.roles = roles
        self.stopped: int | None = None
        self.stop_t_ns: int | None = None
        self.unticked: list[Frame] = []
        self.errors: list[proto.Rec] = []  # ERROR records seen (bus error frames)
        self._out: list[bytes] = []
        self._pending: list[proto.Rec] = []
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        try:
            self._sock.settimeout(connect_timeout)
            self._sock.connect(self.path)
            self._sock.send(proto.pack_hello(name, roles, node))
            buf = self._sock.recv(proto.MAX_DATAGRAM)
        except OSError as e:
            self._sock.close()
            raise BusError(f"cannot join the CAN bus at {self.path}: {e}") from e
        self._sock.settimeout(None)
        if len(buf) == _REC_SIZE and buf[0] == _MSG_STOP:
            reason = _REC.unpack(buf)[4]
            self._sock.close()
            raise BusError(f"the CAN bus at {self.path} refused {name!r}: "
                           f"{proto.STOP_REASONS.get(reason, reason)}")
        if len(buf) != proto.WELCOME_SIZE:
            self._sock.close()
            raise BusError(f"the CAN bus at {self.path} answered with {len(buf)} bytes, "
                           "not a welcome")
        self.welcome = proto.unpack_welcome(buf)
        if self.welcome.magic != proto.MAGIC or self.welcome.version != proto.VERSION:
            self._sock.close()
            raise BusError(f"the CAN bus at {self.path} speaks another protocol "
                           f"(magic {self.welcome.magic:#x}, version {self.welcome.version})")
        self.client = self.welcome.client
        self.quantum_ns = self.welcome.quantum_ns

    # -- sending -------------------------------------------------------------------------
    def send(self, id_: int, data: bytes, t_ns: int = 0, extended: bool = True) -> None:
        """Queue a frame requested at `t_ns`; it leaves with the next done() or flush()."""
        self._out.append(_pack(_MSG_FRAME, _FRAME_EFF if extended else 0, len(data), 0,
                                   id_, t_ns, 0, data))

    def flush(self, extra: bytes = b"") -> None:
        out = self._out
        if extra:
            out.append(extra)
        if not out:
            return
        n = proto.MAX_RECS
        try:
            for i in range(0, len(out), n):
                self._sock.send(b"".join(out[i:i + n]))
        except OSError as e:
            if self.stopped is None:
                raise BusError(f"lost the CAN bus at {self.path}: {e}") from e
        finally:
            out.clear()

    def done(self, t_ns: int, need_ns: int = 0) -> None:
        """Report the quantum up to `t_ns` finished; queued frames go first, same datagram.
        need_ns > t_ns: nothing to do before it, the bus grants no quantum ending at or before
        it (proto.h)."""
        rec = _pack(_MSG_DONE, 0, 0, 0, 0, t_ns, need_ns if need_ns > t_ns else 0, b"")
        out = self._out
        if out and len(out) < proto.MAX_RECS:
            out.append(rec)
            rec = b"".join(out)
            out.clear()
        elif out:
            self.flush(rec)
            return
        try:
            self._sock.send(rec)
        except OSError as e:
            if self.stopped is None:
                raise BusError(f"lost the CAN bus at {self.path}: {e}") from e

    def stop(self, reason: int = proto.STOP_REQUESTED) -> None:
        """Ask the bus to end the run (e.g. the world after a crash)."""
        try:
            self.flush(_REC.pack(_MSG_STOP, 0, 0, 0, reason, 0, 0, b""))
        except BusError:
            pass

    # -- receiving -----------------------------------------------------------------------
    def _read(self, timeout: float | None) -> bool:
        """Read one datagram into the pending records; False on timeout."""
        if timeout is not None:
            r, _, _ = select.select([self._sock], [], [], timeout)
            if not r:
                return False
        try:
            buf = self._sock.recv(proto.MAX_DATAGRAM)
        except OSError as e:
            raise BusError(f"lost the CAN bus at {self.path}: {e}") from e
        self._push(buf)
        return True

    def _push(self, buf: bytes) -> None:
        if not buf:  # the bus closed the connection
            if self.stopped is None:
                self.stopped = proto.STOP_END
            return
        if len(buf) % _REC_SIZE:
            raise BusError(f"the CAN bus sent a datagram of {len(buf)} bytes")
        self._pending.extend(proto.Rec._make(r) for r in _iter_unpack(buf))

    def _frames_until(self, want_tick: bool) -> tuple[list[Frame], proto.Rec | None]:
        """Drain pending records into frames, stopping after a TICK if `want_tick`."""
        frames: list[Frame] = []
        pending = self._pending
        i = 0
        tick = None
        while i < len(pending):
            r = pending[i]
            i += 1
            t = r.type
            if t == _MSG_FRAME:
                frames.append(Frame(r.id, r.data[:r.len], r.t_ns, r.aux, r.src, r.flags))
            elif t == _MSG_TICK:
                if want_tick:
                    tick = r
                    break
            elif t == _MSG_STOP:
                self.stopped = r.id
                self.stop_t_ns = r.t_ns
                i = len(pending)
                break
            elif t == _MSG_ERROR:
                self.errors.append(r)
        del pending[:i]
        return frames, tick

    def wait_tick(self, timeout: float | None = None) -> Tick | None:
        """Block until the next TICK; returns it with the frames delivered before it.

        Returns None when the bus stopped the run (see `stopped`) or on timeout.
        """
        frames: list[Frame] = []
        if timeout is None and not self._pending and self.stopped is None:
            # Fast path: most quanta bring one datagram with the TICK alone, or frames + TICK;
            # the quanta a client is not granted bring their frames alone, before the TICK.
            # Anything else (a STOP, an ERROR, a short datagram) takes the general path below,
            # with the frames taken so far.
            while True:
                try:
                    buf = self._sock.recv(proto.MAX_DATAGRAM)
                except OSError as e:
                    raise BusError(f"lost the CAN bus at {self.path}: {e}") from e
                n = len(buf)
                if n == _REC_SIZE and buf[0] == _MSG_TICK:
                    r = _unpack(buf)
                    return Tick(r[6], r[5], frames)
                if n and n % _REC_SIZE == 0:
                    types = buf[::_REC_SIZE]  # each record's type, its first byte
                    m = types.count(_MSG_FRAME)
                    if m == len(types) or (m == len(types) - 1 and types[-1] == _MSG_TICK):
                        for r in _iter_unpack(buf):
                            if r[0] != _MSG_FRAME:  # the TICK, last
                                return Tick(r[6], r[5], frames)
                            frames.append(Frame(r[4], r[7][:r[2]], r[5], r[6], r[3], r[1]))
                        continue  # frames alone: their TICK comes next
                self._push(buf)
                break
        while True:
            got, tick = self._frames_until(True)
            frames += got
            if tick is not None:
                return Tick(tick.aux, tick.t_ns, frames)
            if self.stopped is not None:
                self.unticked = frames
                return None
            if not self._read(timeout):
                return None

    def recv_frames(self, timeout: float | None = 0.0) -> list[Frame]:
        """Frames received so far (waits up to `timeout` for the first datagram)."""
        if not self._pending and self.stopped is None:
            self._read(timeout)
        while self.stopped is None and self._read(0.0):
            pass
        frames, _ = self._frames_until(False)
        return frames

    def fileno(self) -> int:
        return self._sock.fileno()

    def close(self) -> None:
        try:
            self.flush()
        except BusError:
            pass
        self._sock.close()

    def __enter__(self) -> BusClient:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
