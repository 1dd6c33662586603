# SPDX-License-Identifier: Apache-2.0
"""python-can interface "ima": attach python-can tools (logger, viewer, player, cantools monitor)
to the live virtual CAN bus, e.g. `python -m can.logger -i ima -c RUN/can.sock`. A launched
run's bus admits them listen-only (they are not among its declared clients): they receive every
frame, and sending raises; a bus started by hand takes their frames too."""

from __future__ import annotations

import collections
import logging
import select
import socket

import can

from . import proto

log = logging.getLogger("ima.canbus.pycan")


class ImaBus(can.BusABC):
    """A non-LOCKSTEP CAN client of ima-canbus.

    channel: the bus socket path. Messages carry bus time (end of frame, in seconds) as their
    timestamp; frames sent through it are stamped by the bus with the start of the quantum in
    which it reads them. Classic CAN only (no CAN FD). Extra keyword arguments (also through
    `--bus-kwargs`): `name` (client name on the bus, default "python-can"), `node` (default 0),
    `end_on_stop` (default False: after the run ends the bus stays quiet, as a real idle bus
    would, until the tool is interrupted; True: recv raises CanOperationError instead).
    On a launched run's bus the tool is listen-only (`listen_only`): send raises.
    """

    def __init__(self, channel, can_filters=None, receive_own_messages: bool = False,
                 name: str = "python-can", node: int = 0, end_on_stop: bool = False,
                 **kwargs) -> None:
        self.channel = str(channel)
        self.channel_info = f"IMA virtual CAN bus at {self.channel}"
        self.end_on_stop = bool(end_on_stop)
        self.stopped: int | None = None
        self._rx: collections.deque = collections.deque()
        roles = proto.ROLE_CAN | (proto.ROLE_OWN if receive_own_messages else 0)
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        try:
            sock.settimeout(10.0)
            sock.connect(self.channel)
            sock.send(proto.pack_hello(str(name), roles, int(node)))
            buf = sock.recv(proto.MAX_DATAGRAM)
        except OSError as e:
            sock.close()
            raise can.CanInitializationError(
                f"cannot join the IMA CAN bus at {self.channel}: {e}") from e
        if len(buf) != proto.WELCOME_SIZE:
            sock.close()
            reason = proto.REC.unpack(buf)[4] if len(buf) == proto.REC_SIZE else None
            raise can.CanInitializationError(
                f"the IMA CAN bus at {self.channel} refused us: "
                f"{proto.STOP_REASONS.get(reason, f'{len(buf)}-byte answer')}")
        self.welcome = proto.unpack_welcome(buf)
        if self.welcome.magic != proto.MAGIC or self.welcome.version != proto.VERSION:
            sock.close()
            raise can.CanInitializationError(
                f"the IMA CAN bus at {self.channel} speaks another protocol version")
        sock.settimeout(None)
        self._sock = sock
        self.client = self.welcome.client
        self.bitrate = self.welcome.bitrate
        # a launched run's bus: receive only (nodes/README.md, "Who may join")
        self.listen_only = bool(self.welcome.flags & proto.WELCOME_LISTEN_ONLY)
        super().__init__(channel=channel, can_filters=can_filters, **kwargs)

    def fileno(self) -> int:
        return self._sock.fileno()

    def _ended(self):
        if self.end_on_stop:
            raise can.CanOperationError(
                f"the IMA CAN bus at {self.channel} ended the run: "
                f"{proto.STOP_REASONS.get(self.stopped, self.stopped)}")
        return None, False

    def _read(self, timeout: float | None) -> bool:
        r, _, _ = select.select([self._sock], [], [], timeout)
        if not r:
            return False
        try:
            buf = self._sock.recv(proto.MAX_DATAGRAM)
        except OSError as e:
            raise can.CanOperationError(f"lost the IMA CAN bus at {self.channel}: {e}") from e
        if not buf:
            if self.stopped is None:
                self.stopped = proto.STOP_END
                log.warning("the IMA CAN bus at %s closed the connection", self.channel)
            return True
        if len(buf) % proto.REC_SIZE:
            raise can.CanOperationError(f"the IMA CAN bus sent a {len(buf)}-byte datagram")
        for r in proto.REC.iter_unpack(buf):
            t = r[0]
            if t == proto.MSG_FRAME:
                self._rx.append(r)
            elif t == proto.MSG_STOP and self.stopped is None:
                self.stopped = r[4]
                log.warning("the IMA CAN bus at %s ended the run: %s", self.channel,
                            proto.STOP_REASONS.get(r[4], r[4]))
            elif t == proto.MSG_ERROR:
                self._rx.append(r)
        return True

    def _recv_internal(self, timeout: float | None):
        if not self._rx:
            if self.stopped is not None:
                if self.end_on_stop:
                    return self._ended()
                if timeout:
                    select.select([], [], [], timeout)  # an idle bus: wait out the timeout
                return None, False
            if not self._read(timeout):
                return None, False
            if not self._rx:
                return (self._ended() if self.stopped is not None else (None, False))
        typ, flags, length, src, id_, t_ns, _aux, data = self._rx.popleft()
        if typ == proto.MSG_ERROR:
            msg = can.Message(timestamp=t_ns / 1e9, arbitration_id=id_, is_error_frame=True,
                              is_extended_id=id_ > 0x7FF, data=data[:2],
                              channel=self.channel, is_rx=src != self.client)
            return msg, False
        msg = can.Message(
            timestamp=t_ns / 1e9,
            arbitration_id=id_,
            is_extended_id=bool(flags & proto.FRAME_EFF),
            is_remote_frame=bool(flags & proto.FRAME_RTR),
            dlc=length,
            data=None if flags & proto.FRAME_RTR else data[:length],
            channel=self.channel,
            is_rx=src != self.client,
        )
        return msg, False

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if self.stopped is not None:
            raise can.CanOperationError(f"the IMA CAN bus at {self.channel} has ended the run")
        if self.listen_only:
            raise can.CanOperationError(
                f"the IMA CAN bus at {self.channel} admits this tool listen-only (a run's bus "
                "takes frames from its own clients only): nothing it sends is delivered")
        if msg.is_fd or msg.dlc > 8 or len(msg.data) > 8:
            raise can.CanOperationError("the IMA CAN bus carries classic CAN frames only "
                                        "(at most 8 data bytes)")
        flags = (proto.FRAME_EFF if msg.is_extended_id else 0) | \
                (proto.FRAME_RTR if msg.is_remote_frame else 0)
        data = b"" if msg.is_remote_frame else bytes(msg.data)
        length = msg.dlc if msg.is_remote_frame else len(data)
        rec = proto.REC.pack(proto.MSG_FRAME, flags, length, 0, msg.arbitration_id, 0, 0, data)
        try:
            self._sock.send(rec)
        except OSError as e:
            raise can.CanOperationError(f"cannot send on the IMA CAN bus: {e}") from e

    def shutdown(self) -> None:
        if getattr(self, "_is_shutdown", False):
            return
        super().shutdown()
        try:
            self._sock.close()
        except OSError:
            pass

    @staticmethod
    def _detect_available_configs():
        return []
