# SPDX-License-Identifier: Apache-2.0
"""A run's Unix sockets are its owner's: they live in a directory only the owner may enter,
each is 0600, and the bus and the agents close a connection from another user even when the
file modes let it through."""

from __future__ import annotations

import json
import os
import socket
import stat
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"
NOBODY = 65534

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason="needs root, to connect as another "
                                "user")


def _connect_as(uid: int, path: str) -> str:
    """Connects to the socket as another user (in a child process); what happened."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: becomes `uid`, tries, reports one word
        os.close(r)
        try:
            os.setgid(uid)
            os.setuid(uid)
            s = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
            s.settimeout(5)
            s.connect(path)
            s.sendall(b"\0" * 16)
            word = b"closed" if s.recv(64) == b"" else b"served"
        except PermissionError:
            word = b"denied"
        except (ConnectionResetError, BrokenPipeError):
            word = b"closed"  # closed by the other end before or while it spoke
        except OSError as exc:
            word = ("error " + exc.__class__.__name__).encode()
        os.write(w, word)
        os._exit(0)
    os.close(w)
    os.waitpid(pid, 0)
    with os.fdopen(r, "rb") as f:
        return f.read().decode()


def test_another_user_reaches_neither_the_bus_nor_the_agents(tmp_path):
    run_dir = tmp_path / "run"
    proc = subprocess.Popen([str(ROOT / "ima"), "launch", str(TRIPLEX), "--duration", "8",
                             "--realtime", "--run-dir", str(run_dir), "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (run_dir / "truth.jsonl").exists():
            time.sleep(0.2)
        launch = json.loads((run_dir / "launch.json").read_text())
        sock_dir, bus = Path(launch["socket_dir"]), launch["socket"]
        agent = str(sock_dir / "dds2.sock")
        assert stat.S_IMODE(sock_dir.stat().st_mode) == 0o700
        for path in (bus, agent):
            assert stat.S_IMODE(os.stat(path).st_mode) == 0o600, path
        assert (run_dir / "can.sock").resolve() == Path(bus).resolve()
        # the directory keeps another user out, whatever the sockets' modes
        assert _connect_as(NOBODY, bus) == "denied"
        assert _connect_as(NOBODY, str(run_dir / "can.sock")) == "denied"
        # and with the modes opened wide, the bus and the agent still close on another user
        os.chmod(sock_dir, 0o755)
        os.chmod(bus, 0o666)
        os.chmod(agent, 0o666)
        assert _connect_as(NOBODY, bus) == "closed"
        # an agent takes a new io connection only while its io's is down: until then another
        # user's waits unanswered; when it takes one, it closes another user's
        by_agent = _connect_as(NOBODY, agent)
        assert by_agent in ("closed", "error TimeoutError"), by_agent
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err.decode()[-2000:]
    summary = json.loads(out)
    assert summary["flown_s"] > 7.5 and summary["vote_status"] == "MID3", summary["vote_status"]
    assert json.loads((run_dir / "canbus.json").read_text())["refused_users"] == 1
    if by_agent == "closed":
        assert '"io_refused_user"' in (run_dir / "dds2.jsonl").read_text()
    assert not sock_dir.exists() and not (run_dir / "can.sock").exists()
