# SPDX-License-Identifier: Apache-2.0
"""Processes of the run's own user that reach a live triplex's sockets change nothing: a
hello under a name already taken or a lockstep role it was not declared with is refused; an
undeclared client is listen-only (a python-can tool receives the frames; the frames, FAULT
and STOP an intruder sends are refused); a process that is not a partition of node2's SKE is
closed by node2's agent. The world's truth is bit-identical to the clean run's of the same
seed, and the summary lists every refusal."""

from __future__ import annotations

import json
import socket
import threading
from pathlib import Path

import can
from launch_helpers import TRIPLEX

from ima.canbus import proto
from ima.dds.xch import XchClient

# The clean run of test_launch.py's determinism test (same name, same options, SEED 5 there):
# flown once per session, shared through the launches cache.
SEED = 5
CLEAN = ("det-3-a", dict(system=TRIPLEX, duration_s=60.0, seed=SEED))


def _hello(path: str, name: str, roles: int, node: int = 0) -> tuple[socket.socket, bytes]:
    s = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    s.settimeout(10)
    s.connect(path)
    s.send(proto.pack_hello(name, roles, node))
    return s, s.recv(proto.MAX_DATAGRAM)


def _refusal(path: str, name: str, roles: int, node: int = 0) -> int | None:
    """The STOP reason the bus answers a hello with (None: it welcomed it)."""
    s, answer = _hello(path, name, roles, node)
    s.close()
    return proto.unpack_recs(answer)[0].id if len(answer) == proto.REC_SIZE else None


def _attack(run_dir: Path, seen: dict) -> None:
    launch = json.loads((run_dir / "launch.json").read_text())
    bus = launch["socket"]
    seen["duplicate_io"] = _refusal(bus, "node2/io", proto.ROLE_CAN, 2)
    seen["duplicate_world"] = _refusal(bus, "world", proto.ROLE_CAN | proto.ROLE_LOCKSTEP)
    seen["undeclared_lockstep"] = _refusal(bus, "intruder", proto.ROLE_CAN | proto.ROLE_LOCKSTEP)
    # an undeclared client: welcomed listen-only; a dominant frame, a fault that would drop
    # every frame, a STOP: none is acted on
    s, answer = _hello(bus, "intruder", proto.ROLE_CAN)
    seen["intruder_flags"] = proto.unpack_welcome(answer).flags
    fault = proto.pack_rec(proto.MSG_FAULT, 0xFFFFFFFF, data=bytes([0xFF, 0, 0]), flags=1)
    s.send(proto.pack_frame(0x000, b"\xff" * 8, 0, extended=False) + fault +
           proto.pack_rec(proto.MSG_STOP, proto.STOP_REQUESTED))
    # python-can, as `python -m can.logger -i ima` runs it: it hears the nodes
    with can.Bus(interface="ima", channel=bus, name="logger") as tool:
        seen["heard"] = [tool.recv(timeout=10) for _ in range(5)]
        seen["tool_listen_only"] = tool.listen_only
    s.close()
    # node2's io socket: the agent closes whoever is not a partition of node2's SKE
    try:
        XchClient(str(Path(launch["socket_dir"]) / "dds2.sock"), 2, 10)
        seen["agent"] = "welcomed"
    except (ConnectionError, OSError):
        seen["agent"] = "closed"


def test_outsiders_change_nothing_and_are_listed(launches):
    clean = launches.launch(CLEAN[0], **CLEAN[1])
    run_dir = launches.base / "outsiders"
    seen: dict = {}
    threads: list[threading.Thread] = []

    def on_status(st: dict) -> None:
        if not threads and st.get("t_s", 0) >= 2:  # not in the world's thread: it must go on
            threads.append(threading.Thread(target=_attack, args=(run_dir, seen)))
            threads[0].start()

    run = launches.launch("outsiders", on_status=on_status, **CLEAN[1])
    threads[0].join(timeout=60)
    assert seen.get("agent") == "closed", seen
    assert seen["duplicate_io"] == seen["duplicate_world"] == proto.STOP_REFUSED
    assert seen["undeclared_lockstep"] == proto.STOP_REFUSED
    assert seen["intruder_flags"] & proto.WELCOME_LISTEN_ONLY and seen["tool_listen_only"]
    assert all(m is not None and m.arbitration_id for m in seen["heard"]), seen["heard"]
    # nothing reached the flight: the same truth, the same node traces, bit for bit
    for name in ("truth.jsonl", "world.jsonl", "node1.jsonl", "node2.jsonl", "node3.jsonl"):
        assert (run.run_dir / name).read_bytes() == (clean.run_dir / name).read_bytes(), name
    s = run.summary
    assert s["stopped_by"] is None and s["flown_s"] > 59
    can_refused = [e["detail"] for e in s["refused"] if e["what"] == "can_client"]
    assert sum("refused: duplicate_name" in d for d in can_refused) == 2, can_refused
    assert any("refused: undeclared_lockstep" in d for d in can_refused), can_refused
    assert any(d.startswith("'intruder'") and "listen-only" in d and
               d.endswith("refused 1 FRAME, 1 STOP, 1 FAULT") for d in can_refused), can_refused
    io_refused = [e for e in s["refused"] if e["what"] == "io_client"]
    assert len(io_refused) == 1 and io_refused[0]["by"] == "node2/dds", s["refused"]
    assert clean.summary["refused"] == [] and clean.summary["stopped_by"] is None
