# SPDX-License-Identifier: Apache-2.0
"""`ima launch --live`: a WebSocket client speaking the Foxglove protocol, connected while the
triplex flies, receives the CAN frames, the truth and the vote (node2 voted out after its
kill) as the recording's JSON; the server listens on the loopback interface only; `--speed`
paces the run without changing a bit of the flight."""

from __future__ import annotations

import json
import re
import struct
import subprocess
import threading
import time
from collections import defaultdict
from pathlib import Path

import psutil
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

ROOT = Path(__file__).resolve().parents[2]
IMA = str(ROOT / "ima")
TRIPLEX = str(ROOT / "config" / "systems" / "rpas_triplex.yaml")
FLIGHT = ["--duration", "8", "--kill-node", "node2@3", "--seed", "5", "--no-recording",
          "--json"]
_URL = re.compile(r"live: (ws://127\.0\.0\.1:(\d+))")


def _url_from(proc: subprocess.Popen, err: list[str]) -> tuple[str, int]:
    """Reads the launcher's standard error (kept in err) until it names the live URL."""
    url: list[tuple[str, int]] = []
    seen = threading.Event()

    def read() -> None:
        for line in proc.stderr:
            err.append(line)
            m = _URL.search(line)
            if m and not url:
                url.append((m.group(1), int(m.group(2))))
                seen.set()
    threading.Thread(target=read, daemon=True).start()
    assert seen.wait(60), "".join(err)
    return url[0]


def _listening_address(port: int) -> str:
    for c in psutil.net_connections(kind="tcp"):
        if c.status == psutil.CONN_LISTEN and c.laddr and c.laddr.port == port:
            return c.laddr.ip
    return ""


def _receive(url: str) -> tuple[dict[str, list[dict]], list[str]]:
    """Every message of every channel, from connecting to the end of the run (the server
    closes the connection); the topics advertised."""
    got: dict[str, list[dict]] = defaultdict(list)
    topics: dict[int, str] = {}
    with connect(url, subprotocols=["foxglove.sdk.v1"], open_timeout=10) as ws:
        assert ws.subprotocol == "foxglove.sdk.v1"
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            try:
                m = ws.recv(timeout=1)
            except TimeoutError:
                continue
            except ConnectionClosed:
                break
            if isinstance(m, str):
                op = json.loads(m)
                if op.get("op") == "advertise":
                    subs = []
                    for ch in op["channels"]:
                        topics[ch["id"]] = ch["topic"]
                        subs.append({"id": ch["id"], "channelId": ch["id"]})
                    ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            elif m[0] == 1:  # message data: subscription, log time, payload
                sub, t_ns = struct.unpack_from("<IQ", m, 1)
                rec = json.loads(m[13:])
                rec["_log_time"] = t_ns
                got[topics[sub]].append(rec)
    return got, sorted(topics.values())


def test_a_client_receives_can_truth_and_votes_while_the_triplex_flies(tmp_path):
    run = tmp_path / "live"
    proc = subprocess.Popen([IMA, "launch", TRIPLEX, *FLIGHT, "--live", "--live-port", "0",
                             "--speed", "3", "--run-dir", str(run)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    err: list[str] = []
    try:
        url, port = _url_from(proc, err)
        assert _listening_address(port) == "127.0.0.1"
        got, advertised = _receive(url)
        out = proc.stdout.read()
        assert proc.wait(timeout=120) == 0, "".join(err)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    summary = json.loads(out)
    assert summary["live_url"] == url
    # every topic of the recording is advertised before the flight starts
    for topic in ("/can/frames", "/vote", "/world/truth", "/world/location", "/node1/schedule",
                  "/node3/hm", "/can/signals/ACT_CMD_A"):
        assert topic in advertised
    frames = got["/can/frames"]
    assert len(frames) > 2000
    assert all({"id", "t_ns", "seq", "from"} <= f.keys() for f in frames)
    assert all(f["_log_time"] == f["t_ns"] for f in frames[:100])
    assert {f["name"] for f in frames} >= {"ACT_CMD_A", "ACT_CMD_B", "ACT_CMD_C", "AHRS_ATT"}
    # the truth as it flies, to the end of the run
    truth = got["/world/truth"]
    times = [r["t_ns"] for r in truth]
    assert times == sorted(times) and times[-1] >= 7.5e9
    assert all(isinstance(r["alt_ft"], float) for r in truth)
    # the vote, from its first status to node2 voted out after its kill at 3 s
    votes = got["/vote"]
    assert votes and votes[0]["kind"] == "vote"
    out_ = [v for v in votes if v["kind"] == "voted_out"]
    assert out_ and out_[0]["node"] == "node2" and out_[0]["t_ns"] >= 3e9
    # nothing served twice nor lost between the client and the trace
    seqs = [f["seq"] for f in frames]
    assert seqs == sorted(set(seqs))
    assert summary["live_messages"] >= sum(len(v) for v in got.values())


def test_speed_paces_the_run_without_changing_the_flight(tmp_path):
    paced, fast = tmp_path / "paced", tmp_path / "fast"
    for run, extra in ((paced, ["--speed", "4"]), (fast, [])):
        p = subprocess.run([IMA, "launch", TRIPLEX, *FLIGHT, *extra, "--run-dir", str(run)],
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
    # 8 emulated seconds at 4x take at least 2 s of wall time
    wall = json.loads((paced / "summary.json").read_text())["wall_s"]
    assert wall >= 2.0
    assert (paced / "truth.jsonl").read_bytes() == (fast / "truth.jsonl").read_bytes()
    cmd = json.loads((paced / "launch.json").read_text())["commands"]["canbus"]
    assert cmd[cmd.index("--pace") + 1] == "4"


def test_speed_and_realtime_exclude_each_other(tmp_path):
    p = subprocess.run([IMA, "launch", TRIPLEX, "--duration", "1", "--speed", "2",
                        "--realtime", "--run-dir", str(tmp_path / "r")],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2
    assert "--speed paces a lockstep run" in p.stderr
    assert "Traceback" not in p.stderr
