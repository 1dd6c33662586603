# SPDX-License-Identifier: Apache-2.0
"""The launcher's end of the bus's control channel (ima-canbus --control-fd): a socketpair whose
other end the bus inherits, so that nobody else can arm a bus fault, stop the run or name the
processes of the declared clients through it (proto.h, "Control channel")."""

from __future__ import annotations

import socket

from . import proto


class BusControl:
    """Make one before starting the bus: pass `child_fd` to it (`--control-fd`, and in the
    Popen's pass_fds), then call `started()`."""

    def __init__(self) -> None:
        self._sock, self._child = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self._child.set_inheritable(True)

    @property
    def child_fd(self) -> int:
        return self._child.fileno()

    def started(self) -> None:
        """The bus holds its end now: ours of it is closed."""
        self._child.close()

    def _send(self, rec: bytes) -> bool:
        try:
            self._sock.send(rec)
            return True
        except OSError:  # the bus has gone: there is nothing left to stop or arm
            return False

    def stop(self) -> bool:
        """Ends the run (the statistics' stopped_by is "launcher"); False if the bus is gone."""
        return self._send(proto.pack_rec(proto.MSG_STOP, proto.STOP_REQUESTED))

    def process(self, node: int, pid: int) -> bool:
        """Names the process of a node (0: the world): the bus admits a client declared for
        that node only from that process or a child of it (a SKE's partitions)."""
        return self._send(proto.pack_rec(proto.MSG_PROCESS, node, pid))

    def arm(self, fault_rec: bytes) -> bool:
        """Arms a bus fault: one FAULT record as proto.h lays it out."""
        return self._send(fault_rec)

    def close(self) -> None:
        self._child.close()
        self._sock.close()
