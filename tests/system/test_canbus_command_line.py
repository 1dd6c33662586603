# SPDX-License-Identifier: Apache-2.0
"""ima-canbus's command line and set-up: a bad option is named and exits 2 before anything
opens; a bus that cannot open its socket, trace or statistics exits 1 saying which."""

from __future__ import annotations

import json
import os
import socket
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUS = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build")) / "nodes" / "ima-canbus"


def _bus(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(BUS), *args], capture_output=True, text=True, timeout=30)


@pytest.mark.parametrize(("args", "says"), [
    (["--bitrate", "999"], "--bitrate must be 1000..10000000"),
    (["--quantum-us", "0"], "--quantum-us must be 1..10000000"),
    (["--lockstep-clients", "251"], "--lockstep-clients must be 0..250"),
    (["--duration", "soon"], "--duration must be a number of seconds"),
    (["--duration", "-1"], "--duration must be a number of seconds"),
    (["--end-ns", "-5"], "--end-ns must be >= 0"),
    (["--max-clients", "0"], "--max-clients must be 1..250"),
    (["--fault", "no_such_class:fid=f1,at=1"], "ima-canbus: "),
    (["--fault", "drop:fid=f1,at=1,id=0x100", "--fault", "drop:fid=f1,at=2,id=0x100"],
     "--fault: fid f1 given twice"),
    (["--kill-node", "2"], "--kill-node must be NODE@SECONDS, e.g. 2@120"),
    (["--kill-node", "@5"], "--kill-node must be NODE@SECONDS"),
    (["--kill-node", "0@5"], "--kill-node must be NODE@SECONDS"),
    (["--hang-node", "2@"], "--hang-node must be NODE@SECONDS, e.g. 2@120"),
    (["--hang-node", "2@-1"], "--hang-node must be NODE@SECONDS"),
    (["--client-order", ",".join(f"n{i}" for i in range(65))], "--client-order: at most 64"),
    (["--client-order", "x" * 33], "--client-order: at most 64 names of at most 32 characters"),
    (["--max-rejects", "-1"], "--max-rejects must be >= 0"),
    (["--send-timeout-ms", "0"], "--send-timeout-ms must be 1..3600000"),
    (["--client-buffer", "-1"], "--client-buffer must be >= 0"),
    (["--gap-bits", "1001"], "--gap-bits must be 0..1000"),
    (["--duration", "1e10"], "--duration must be a number of seconds"),
    (["--duration", "nan"], "--duration must be a number of seconds"),
    (["--bitrate", "1x"], "--bitrate must be 1000..10000000"),
    (["--bitrate", "99999999999999999999"], "--bitrate must be 1000..10000000"),
    (["--control-fd", "2"], "--control-fd must be a descriptor number >= 3"),
    (["--kill-node", "2@1e10"], "--kill-node must be NODE@SECONDS"),
    (["--kill-node", "2@nan"], "--kill-node must be NODE@SECONDS"),
    (["--kill-node", "2@5x"], "--kill-node must be NODE@SECONDS"),
    (["--kill-node", "9" * 40 + "@5"], "--kill-node must be NODE@SECONDS"),
    (["--pace", "0"], "--pace must be a factor > 0"),
    (["--pace", "-2"], "--pace must be a factor > 0"),
    (["--pace", "nan"], "--pace must be a factor > 0"),
    (["--pace", "2x"], "--pace must be a factor > 0"),
    (["--pace", "1e7"], "--pace must be a factor > 0"),
    (["--pace", "2", "--realtime"], "--realtime and --pace exclude each other"),
    (["--no-such-option"], "usage: ima-canbus"),
    ([], "usage: ima-canbus"),  # no --socket
    (["extra"], "usage: ima-canbus"),
])
def test_a_bad_command_line_is_a_usage_error(tmp_path, args, says):
    sock = tmp_path / "can.sock"
    p = _bus(*([] if args == [] else ["--socket", str(sock)]), *args)
    assert p.returncode == 2, p.stderr
    assert says in p.stderr
    assert not sock.exists()


@pytest.mark.parametrize("decl", [
    "world",              # no roles, no node
    "world:can",          # no node
    ":can:0",             # no name
    "x" * 33 + ":can:1",  # a name longer than the bus keeps
    "world::0",           # no role
    "world:can+:0",       # an empty role
    "world:can+radio:0",  # no such role
    "world:own+x:0",
    "world:can:-1",       # a node number out of range
    "world:can:4294967296",
    "world:can:one",
])
def test_a_bad_client_declaration_is_a_usage_error(tmp_path, decl):
    sock = tmp_path / "can.sock"
    p = _bus("--socket", str(sock), "--client", decl)
    assert p.returncode == 2, p.stderr
    assert "--client must be NAME:ROLES:NODE" in p.stderr
    assert not sock.exists()


def test_every_role_is_declared(tmp_path):
    """can, lockstep and own, in any order, joined by '+': the bus starts."""
    sock = tmp_path / "can.sock"
    p = _bus("--socket", str(sock), "--client", "w:own+lockstep+can:0", "--client",
             "n1/io:can:1", "--duration", "0", "-q")
    assert p.returncode == 0, p.stderr


def test_help():
    p = _bus("--help")
    assert p.returncode == 0 and p.stdout.startswith("usage: ima-canbus --socket PATH"), p


def test_a_run_with_every_option_it_can_take_ends_on_time(tmp_path):
    stats = tmp_path / "stats.json"
    p = _bus("--socket", str(tmp_path / "can.sock"), "--duration", "0.01", "-q",
             "--stats", str(stats), "--kill-node", "2@5", "--hang-node", "3@5",
             "--client-order", "a,b", "--bus-off-recovery", "--client", "a:can+lockstep:1",
             "--max-rejects", "3", "--send-timeout-ms", "100", "--client-buffer", "4096",
             "--gap-bits", "3", "--bitrate", "500000", "--quantum-us", "1000",
             "--max-clients", "4", "--lockstep-clients", "0")
    assert p.returncode == 0, p.stderr
    assert '"quanta":10' in stats.read_text()


@pytest.mark.parametrize("what", ["socket", "trace", "stats", "long_path"])
def test_what_the_bus_cannot_open_fails_it(tmp_path, what):
    sock = tmp_path / "can.sock"
    args = ["--socket", str(sock), "--end-ns", "0", "-q"]
    if what == "socket":
        args[1] = str(tmp_path / "missing" / "can.sock")
    elif what == "long_path":
        args[1] = str(tmp_path / ("s" * 120))
    elif what == "trace":
        args += ["--trace", str(tmp_path / "missing" / "trace.jsonl")]
    else:
        args += ["--stats", str(tmp_path / "missing" / "stats.json")]
    p = _bus(*args)
    assert p.returncode == 1
    said = "cannot write" if what == "stats" else "cannot open the bus on"
    assert said in p.stderr
    if what == "long_path":
        assert "File name too long" in p.stderr


def test_a_live_socket_is_not_taken_over_a_stale_one_is(tmp_path):
    sock = tmp_path / "can.sock"
    live = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    live.bind(str(sock))
    live.listen(1)
    try:
        p = _bus("--socket", str(sock), "--end-ns", "0", "-q")
        assert p.returncode == 1 and "Address already in use" in p.stderr, p.stderr
    finally:
        live.close()  # the file stays: a stale socket of an earlier run
    assert sock.exists()
    p = _bus("--socket", str(sock), "--end-ns", "0", "-q")
    assert p.returncode == 0, p.stderr


def test_a_full_disk_under_its_trace_or_statistics_fails_the_bus(tmp_path):
    base = ["--socket", str(tmp_path / "can.sock"), "--duration", "0.01", "-q"]
    p = _bus(*base, "--stats", "/dev/full")
    assert p.returncode == 1 and "cannot write /dev/full: Input/output error" in p.stderr
    p = _bus(*base, "--trace", "/dev/full")
    assert p.returncode == 1 and "writing the trace failed" in p.stderr
    # Both on standard output: the trace's lines, then the statistics.
    p = _bus(*base, "--trace", "-", "--stats", "-")
    assert p.returncode == 0, p.stderr
    lines = [json.loads(line) for line in p.stdout.splitlines()]
    assert lines[-2]["kind"] == "bus_stop" and lines[-1]["quanta"] == 2, lines

