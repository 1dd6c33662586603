# SPDX-License-Identifier: Apache-2.0
"""ima-dds-node's command line: a bad or missing option is named and exits 2 before DDS
starts; a configuration, trace, socket or statistics file it cannot use exits 1 saying
which."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
AGENT = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build")) / "nodes" / "dds" / "ima-dds-node"
CONFIG = ROOT / "config" / "dds" / "cyclonedds-loopback.xml"


def _agent(*args: str, config: str | None = str(CONFIG)) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "IMA_DDS_CONFIG"}
    if config is not None:
        env["IMA_DDS_CONFIG"] = config
    return subprocess.run([str(AGENT), *args], capture_output=True, text=True, timeout=30,
                          env=env)


def _required(tmp_path: Path) -> list[str]:
    return ["--node", "1", "--nodes", "3", "--socket", str(tmp_path / "xch.sock"),
            "--domain", "7"]


@pytest.mark.parametrize(("args", "says"), [
    (["--node", "4"], "--node wants 1..3 (got 4)"),
    (["--nodes", "0"], "--nodes wants 1..3 (got 0)"),
    (["--domain", "233"], "--domain wants 0..232 (got 233)"),
    (["--xch-timeout-us", "0"], "--xch-timeout-us wants 1..60000000"),
    (["--lease-ms", "9"], "--lease-ms wants 10..3600000"),
    (["--deadline-ms", "x"], "--deadline-ms wants 1..3600000"),
    (["--startup-timeout-ms", "-1"], "--startup-timeout-ms wants 0..3600000"),
    (["--fault", "dds_nonsense:fid=a,at=1"], "ima-dds-node: "),
    (["--no-such-option"], "unknown option or missing value: --no-such-option"),
    (["extra"], "unexpected argument extra"),
    (["--node", "3", "--nodes", "2"], "--node 3 is not one of --nodes 2"),
    (["--bind-device", "x" * 16], "--bind-device name too long"),
    (["--node", "1x"], "--node wants 1..3"),
    (["--node", ""], "--node wants 1..3"),
    (["--domain", "99999999999999999999"], "--domain wants 0..232"),
    (["--security", ""], "--security wants a directory"),
    (["--security", "d" * 5000], "--security wants a directory"),
    (["--ske-pid-fd", "2"], "--ske-pid-fd wants an open descriptor >= 3"),
    (["--ske-pid-fd", "999"], "--ske-pid-fd wants an open descriptor >= 3"),
])
def test_a_bad_command_line_is_a_usage_error(tmp_path, args, says):
    p = _agent(*_required(tmp_path), *args)
    assert p.returncode == 2, p.stderr
    assert says in p.stderr
    assert p.stdout == ""


@pytest.mark.parametrize("missing", ["--node", "--nodes", "--socket", "--domain"])
def test_required_options_and_help(tmp_path, missing):
    args = _required(tmp_path)
    del args[args.index(missing):args.index(missing) + 2]
    p = _agent(*args)
    assert p.returncode == 2
    assert "--node, --nodes, --socket and --domain are required" in p.stderr
    p = _agent("--help")
    assert p.returncode == 0 and p.stdout.startswith("usage: ima-dds-node"), p


def test_no_dds_configuration_is_refused(tmp_path):
    """Cyclone's default would send multicast on every interface."""
    p = _agent(*_required(tmp_path), config=None)
    assert p.returncode == 2 and "no Cyclone DDS configuration" in p.stderr
    p = _agent(*_required(tmp_path), config="")
    assert p.returncode == 2 and "no Cyclone DDS configuration" in p.stderr
    p = _agent(*_required(tmp_path), "--config", str(tmp_path / "missing.xml"))
    assert p.returncode == 1
    assert "cannot read the DDS configuration" in p.stderr
    # a file:// URI names the same file
    p = _agent(*_required(tmp_path), "--config", f"file://{tmp_path}/missing.xml")
    assert p.returncode == 1
    assert f"cannot read the DDS configuration {tmp_path}/missing.xml" in p.stderr


def test_an_unwritable_trace_stops_the_agent(tmp_path):
    p = _agent(*_required(tmp_path), "--trace", str(tmp_path / "missing" / "t.jsonl"))
    assert p.returncode == 1
    assert "cannot write the trace" in p.stderr
    assert not (tmp_path / "xch.sock").exists()


@pytest.mark.parametrize(("where", "says"), [
    ("file", "exists and is not a socket"),
    ("missing/xch.sock", "cannot listen at"),
    ("s" * 120, "socket path longer than"),
    ("live.sock", "another agent is listening at"),
])
def test_a_socket_it_cannot_take_stops_the_agent(tmp_path, where, says):
    path = tmp_path / where
    (tmp_path / "file").write_text("")
    live = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    live.bind(str(tmp_path / "live.sock"))
    live.listen(1)
    try:
        args = _required(tmp_path)
        args[args.index("--socket") + 1] = str(path)
        p = _agent(*args)
    finally:
        live.close()
    assert p.returncode == 1, p.stderr
    assert says in p.stderr
    assert p.stdout == ""


def test_a_stale_socket_is_taken_over_and_unwritable_statistics_fail_the_run(tmp_path, domain):
    """The socket of an agent that died is replaced; the run ends on SIGTERM, and statistics
    that cannot be written make it a failure."""
    sock = tmp_path / "xch.sock"
    stale = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    stale.bind(str(sock))
    stale.close()
    env = dict(os.environ, IMA_DDS_CONFIG=str(CONFIG))
    stats = tmp_path / "missing" / "stats.json"
    p = subprocess.Popen([str(AGENT), "--node", "1", "--nodes", "1", "--socket", str(sock),
                          "--domain", str(domain), "--startup-timeout-ms", "0", "-q",
                          "--stats", str(stats)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert p.stdout.readline() == "ready\n"
        p.send_signal(signal.SIGTERM)
        _, err = p.communicate(timeout=30)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == 1, err
    assert f"cannot write statistics to {stats}" in err
    assert not sock.exists()  # removed at the end
