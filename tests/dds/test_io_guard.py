# SPDX-License-Identifier: Apache-2.0
"""An agent told its node's SKE (--ske-pid-fd) takes as io only a partition process of that
SKE (one of its children): another process of the same user that connects to the io socket is
closed at once, even while io's link is up, and listed in the statistics; io goes on."""

from __future__ import annotations

import os
import subprocess
import sys

from dds_helpers import inputs_for

from ima.dds.agent import start_agent
from ima.dds.xch import XchClient

# Plays io, or an intruder: HELLO, then says whether the agent answered with a WELCOME.
_CONNECT = ("import sys\nfrom ima.dds.xch import XchClient\n"
            "try:\n    XchClient(sys.argv[1], 1, 10)\n    print('welcomed')\n"
            "except (ConnectionError, OSError):\n    print('closed')\n")


def _connect(sock, via_another_process: bool = False) -> str:
    """Connects from a child of this process, or from a grandchild (not a child of the SKE)."""
    cmd = [sys.executable, "-c", _CONNECT, str(sock)]
    if via_another_process:
        cmd = [sys.executable, "-c", "import subprocess, sys; "
               "sys.exit(subprocess.run(sys.argv[1:]).returncode)", *cmd]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=60).stdout.strip()


def _io_child(sock, ready: int, go: int) -> int:
    """Forks io, a child of this process: it connects, says so, waits for `go`, exchanges one
    frame and reports it (b"ok") on `ready`."""
    pid = os.fork()
    if pid:
        return pid
    try:
        io = XchClient(str(sock), 1, 10)
        os.write(ready, b"up")
        os.read(go, 1)
        ok = io.exchange(0, 0, inputs_for(1, 0, 0b1)).present == 0b1
        os.write(ready, b"ok" if ok else b"no")
    finally:
        os._exit(0)


def test_only_a_child_of_the_ske_may_be_io(run_dir, domain):
    r, w = os.pipe()
    agent = start_agent(1, 1, run_dir, domain, extra=["--ske-pid-fd", str(r)], fds=(r,),
                        wait=True)
    os.close(r)
    ready_r, ready_w = os.pipe()
    go_r, go_w = os.pipe()
    try:
        os.write(w, f"{os.getpid()}\n".encode())  # this test plays the node's SKE
        os.close(w)
        assert _connect(agent.socket, via_another_process=True) == "closed"
        pid = _io_child(agent.socket, ready_w, go_r)
        assert os.read(ready_r, 2) == b"up"
        assert _connect(agent.socket, via_another_process=True) == "closed"  # while io is up
        os.write(go_w, b"g")
        assert os.read(ready_r, 2) == b"ok"  # io was not disturbed
        os.waitpid(pid, 0)
        assert _connect(agent.socket) == "welcomed"  # io restarted: a child of the SKE again
    finally:
        agent.stop()
        for fd in (ready_r, ready_w, go_r, go_w):
            os.close(fd)
    st = agent.read_stats()
    assert st["io_refused"] == 2 and st["io_connections"] == 2, st
    assert [e["what"] for e in st["refusals"]] == ["io_client", "io_client"]
    assert "is not a partition of node1's SKE" in st["refusals"][0]["detail"]
    assert len(agent.of_kind("io_refused_process")) == 2
    assert agent.of_kind("io_ske", ske_pid=os.getpid())
