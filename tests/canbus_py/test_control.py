# SPDX-License-Identifier: Apache-2.0
"""The real ima-canbus as the launcher runs it: its control channel (a socketpair it inherits)
ends the run with stopped_by "launcher"; the world's STOP still ends it ("world"); a tool's
STOP does not."""

from __future__ import annotations

import json
import os
import subprocess
import time

import can
import pytest

from ima.canbus import proto
from ima.canbus.client import BusClient
from ima.canbus.control import BusControl
from ima.errors import ImaError
from ima.launch.options import binary

LOCK = proto.ROLE_CAN | proto.ROLE_LOCKSTEP


@pytest.fixture
def bus(tmp_path):
    """bus() -> (socket path, stats path, BusControl, process) of a started ima-canbus that
    knows one client, the world."""
    started = []

    def start():
        try:
            exe = str(binary("nodes/ima-canbus"))
        except ImaError as exc:
            pytest.fail(str(exc))
        sock, stats = tmp_path / "can.sock", tmp_path / "canbus.json"
        control = BusControl()
        proc = subprocess.Popen([exe, "--socket", str(sock), "--lockstep-clients", "1",
                                 "--stats", str(stats), "--client", "world:can+lockstep:0",
                                 "--control-fd", str(control.child_fd), "-q"],
                                pass_fds=(control.child_fd,))
        control.started()
        control.process(0, os.getpid())  # the world is this test
        started.append((proc, control))
        deadline = time.monotonic() + 10
        while not sock.exists():
            if proc.poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"ima-canbus did not open {sock} (status {proc.poll()})")
            time.sleep(0.01)
        return str(sock), stats, control, proc

    yield start
    for proc, control in started:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        control.close()


def _stats(path) -> dict:
    return json.loads(path.read_text())


def test_the_launcher_stops_the_run_on_its_channel(bus):
    sock, stats, control, proc = bus()
    world = BusClient(sock, "world", LOCK)
    with can.Bus(interface="ima", channel=sock, name="logger") as tool:
        assert tool.listen_only
        with pytest.raises(can.CanOperationError, match="listen-only"):
            tool.send(can.Message(arbitration_id=0x10, data=b"\x01"))
        tool._sock.send(proto.pack_rec(proto.MSG_STOP, proto.STOP_REQUESTED))  # past the check
        world.done(world.wait_tick().t_until)
        assert world.wait_tick() is not None  # the tool's STOP stopped nothing
        assert control.stop()
        assert world.wait_tick(timeout=10) is None and world.stopped == proto.STOP_REQUESTED
    world.close()
    assert proc.wait(timeout=10) == 0
    st = _stats(stats)
    assert st["stopped_by"] == "launcher" and st["refused_records"] == 1
    assert [e["what"] for e in st["refusals"]] == ["can_client"]
    assert st["refusals"][0]["detail"].startswith("'logger' (client 1, listen-only, pid ")
    assert st["refusals"][0]["detail"].endswith("refused 1 STOP")
    assert not control.stop()  # the bus has gone


def test_the_world_may_still_stop_the_run(bus):
    sock, stats, control, proc = bus()
    world = BusClient(sock, "world", LOCK)
    world.wait_tick()
    world.stop()
    assert world.wait_tick() is None and world.stopped == proto.STOP_REQUESTED
    world.close()
    assert proc.wait(timeout=10) == 0
    assert _stats(stats)["stopped_by"] == "world"
