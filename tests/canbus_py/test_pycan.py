# SPDX-License-Identifier: Apache-2.0
"""The python-can interface "ima": in-process use, and can.logger / can.player as tools."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import can
import pytest

from ima.canbus import proto
from ima.canbus.codec import MESSAGES

GPS = MESSAGES["GPS_POS"]


def _gps_every_100ms(t_from, t_until):
    if t_from % 100_000_000 == 0:
        return [(t_from, GPS.frame_id, GPS.encode(47.0 + t_from / 1e12, 8.0))]
    return []


def test_python_can_finds_the_interface(fakebus, sock_path):
    fakebus(lockstep_clients=0, realtime=True, injector=_gps_every_100ms, end_ns=3 * 10**9)
    with can.Bus(interface="ima", channel=sock_path, receive_own_messages=True) as bus:
        assert type(bus).__name__ == "ImaBus"
        msg = bus.recv(2.0)
        assert msg is not None and msg.arbitration_id == GPS.frame_id and msg.is_extended_id
        assert msg.is_rx and msg.dlc == 8
        # bus time of the frame's end: a request at k*100 ms plus 160 bit times at 1 Mbit/s
        assert round(msg.timestamp * 1e9) % 100_000_000 == proto.frame_bits(True, 8) * 1000
        bus.send(can.Message(arbitration_id=0x123, data=b"\x01\x02", is_extended_id=False))
        deadline = time.monotonic() + 2
        while time.monotonic() < deadline:
            m = bus.recv(0.5)
            if m is not None and m.arbitration_id == 0x123:
                break
        else:
            pytest.fail("own frame did not come back")
        assert not m.is_rx and not m.is_extended_id and bytes(m.data) == b"\x01\x02"
        with pytest.raises(can.CanOperationError):
            bus.send(can.Message(arbitration_id=1, data=bytes(12), is_fd=True))


def test_refused_and_missing_bus_are_initialisation_errors(tmp_path):
    with pytest.raises(can.CanInitializationError, match="cannot join"):
        can.Bus(interface="ima", channel=str(tmp_path / "none.sock"))


def test_can_logger_records_the_bus(fakebus, sock_path, tmp_path):
    bus = fakebus(lockstep_clients=0, realtime=True, injector=_gps_every_100ms,
                  end_ns=4 * 10**9)
    out = tmp_path / "bus.log"
    p = subprocess.Popen([sys.executable, "-m", "can.logger", "-i", "ima", "-c", sock_path,
                          "-f", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)
    bus.join(15)
    time.sleep(0.3)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=15)
    assert p.returncode == 0, stderr
    assert "ImaBus" in stdout
    msgs = list(can.LogReader(str(out)))
    assert len(msgs) >= 10, stderr
    assert all(m.arbitration_id == GPS.frame_id and m.is_extended_id for m in msgs)
    ts = [round(m.timestamp * 1e9) for m in msgs]
    assert all(b - a == 100_000_000 for a, b in zip(ts, ts[1:]))  # bus time, not wall time


def test_can_player_puts_frames_on_the_bus(fakebus, sock_path, tmp_path):
    bus = fakebus(lockstep_clients=0, realtime=True, end_ns=None)
    log = tmp_path / "in.log"
    with can.Logger(str(log)) as w:
        for i in range(5):
            w(can.Message(timestamp=100.0 + 0.05 * i, arbitration_id=0x18FF0000 + i,
                          data=bytes([i] * 4), is_extended_id=True))
    p = subprocess.run([sys.executable, "-m", "can.player", "-i", "ima", "-c", sock_path,
                        str(log)], capture_output=True, text=True, timeout=30)
    assert p.returncode == 0, p.stderr
    time.sleep(0.2)
    bus.stop_reason = proto.STOP_REQUESTED
    bus.join(5)
    got = [(e.id, e.data) for e in bus.trace]
    assert got == [(0x18FF0000 + i, bytes([i] * 4)) for i in range(5)]
