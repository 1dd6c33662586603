# SPDX-License-Identifier: Apache-2.0
"""The real ima-canbus skipping the quanta a lockstep client says it does not need (proto.h:
a DONE whose aux is later than the grant): that client is granted only the quantum that holds
its next work, the other client every quantum, and the bus counts both."""

from __future__ import annotations

import json
import subprocess
import threading
import time

import pytest

from ima.canbus import proto
from ima.canbus.client import BusClient
from ima.errors import ImaError
from ima.launch.options import binary

MS = 1_000_000


def _client(sock, name, roles, node, plan, grants):
    """Answers every TICK; plan maps a granted time to the `need_ns` of its DONE."""
    c = BusClient(sock, name, roles, node)
    try:
        while (tick := c.wait_tick()) is not None:
            grants.append(tick.t_until)
            c.done(tick.t_until, need_ns=plan.get(tick.t_until, 0))
    finally:
        c.close()


def test_a_client_is_granted_only_the_quanta_it_needs(tmp_path):
    try:
        exe = str(binary("nodes/ima-canbus"))
    except ImaError as exc:
        pytest.fail(str(exc))
    sock, stats = tmp_path / "can.sock", tmp_path / "canbus.json"
    bus = subprocess.Popen([exe, "--socket", str(sock), "--lockstep-clients", "2",
                            "--quantum-us", "10000", "--end-ns", str(100 * MS),
                            "--stats", str(stats), "-q"])
    try:
        deadline = time.monotonic() + 10
        while not sock.exists():
            assert bus.poll() is None and time.monotonic() < deadline, "no bus socket"
            time.sleep(0.01)
        every, some = [], []
        # "ske": after the quantum ending at 10 ms, its next work is at 35 ms (the quantum
        # [30, 40) holds it); a need at the grant itself is no skip; then nothing until the end
        plan = {10 * MS: 35 * MS, 40 * MS: 40 * MS, 50 * MS: 100 * MS}
        threads = [threading.Thread(target=_client, args=(str(sock), "world", proto.ROLE_CAN |
                                                          proto.ROLE_LOCKSTEP, 0, {}, every)),
                   threading.Thread(target=_client, args=(str(sock), "ske", proto.ROLE_LOCKSTEP,
                                                          1, plan, some))]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        assert bus.wait(30) == 0
    finally:
        if bus.poll() is None:
            bus.kill()
            bus.wait()
    assert every == [k * 10 * MS for k in range(1, 11)]
    assert some == [10 * MS, 40 * MS, 50 * MS]
    clients = {c["name"]: c for c in json.loads(stats.read_text())["clients"]}
    assert (clients["world"]["ticks"], clients["world"]["ticks_skipped"]) == (10, 0)
    assert (clients["ske"]["ticks"], clients["ske"]["ticks_skipped"]) == (3, 7)
