# SPDX-License-Identifier: Apache-2.0
"""`ima launch` as a user runs it: determinism with 1 and 3 nodes, DDS on loopback only, a
DDS tool listening to a live run, real time, Ctrl-C, bad options."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from launch_helpers import ROOT, SIMPLEX, TRIPLEX

from ima.flight.summary import read_jsonl

IMA = str(ROOT / "ima")
SEED = 5
# Traces that must be byte-identical for the same seed (the DDS agents' traces are stamped
# with the wall clock, by design, and are not among them).
DETERMINISTIC = ("truth.jsonl", "can.jsonl", "world.jsonl", "node1.jsonl")


def _files(run, names):
    return {n: (run.run_dir / n).read_bytes() for n in names}


@pytest.mark.parametrize("system,nodes", [(SIMPLEX, 1), (TRIPLEX, 3)], ids=["simplex", "triplex"])
def test_same_seed_same_traces(launches, system, nodes):
    names = DETERMINISTIC + tuple(f"node{k}.jsonl" for k in range(2, nodes + 1))
    a = launches.launch(f"det-{nodes}-a", system=system, duration_s=60.0, seed=SEED)
    b = launches.launch(f"det-{nodes}-b", system=system, duration_s=60.0, seed=SEED)
    fa, fb = _files(a, names), _files(b, names)
    for n in names:
        assert fa[n], f"{n} is empty"
        assert fa[n] == fb[n], f"{n} differs between two runs with seed {SEED}"
    c = launches.launch(f"det-{nodes}-c", system=system, duration_s=60.0, seed=SEED + 1)
    assert (c.run_dir / "truth.jsonl").read_bytes() != fa["truth.jsonl"]


def _run_pids(marker: str) -> dict[int, str]:
    """Processes whose command line mentions `marker` (the run directory)."""
    out = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            cmd = Path(f"/proc/{name}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if marker in cmd:
            out[int(name)] = cmd
    return out


def test_dds_stays_on_loopback_and_a_tool_can_listen(launches, tmp_path):
    """While a triplex runs: every socket and multicast membership of its processes is on
    loopback; the Python cyclonedds listener receives the nodes' health on the run's domain.
    The run has DDS Security off: the cyclonedds wheel carries no security plugins, so it
    could not join a secure run (tests/dds/test_security.py shows that it cannot)."""
    from ima.dds import netcheck

    seen: dict = {}
    run_dir = launches.base / "loopback"

    def on_status(st: dict) -> None:
        if seen or st.get("t_s", 0) < 20:
            return
        pids = _run_pids(str(run_dir))
        seen["pids"] = pids
        seen["problems"] = netcheck.check_loopback_only(list(pids))
        domain = json.loads((run_dir / "launch.json").read_text())["dds_domain"]
        # not waited for here: the run must go on publishing while the listener listens
        seen["listen"] = subprocess.Popen(
            [sys.executable, "-m", "ima.dds.listen", "--domain", str(domain), "--topic",
             "rpas_NodeHealth", "--count", "30", "--json"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    run = launches.launch("loopback", duration_s=300.0, seed=SEED, on_status=on_status,
                          dds_security="off")
    assert seen, "the run ended before the check"
    agents = [p for p, c in seen["pids"].items() if "ima-dds-node" in c]
    assert len(agents) == 3, seen["pids"]
    assert seen["problems"] == [], seen["problems"]
    listen = seen["listen"]
    out, err = listen.communicate(timeout=60)
    assert listen.returncode == 0, err
    samples = [json.loads(line) for line in out.splitlines() if line.strip()]
    health = [s["sample"] for s in samples if s.get("valid") and s["topic"] == "rpas_NodeHealth"]
    assert len(health) >= 6, samples
    assert {h["node"] for h in health} == {1, 2, 3}, health
    assert all(h["membership"] == 0b111 for h in health), health
    assert not run.summary["crashed"]


def test_realtime_triplex_runs(launches):
    run = launches.launch("realtime", duration_s=8.0, seed=SEED, realtime=True)
    assert run.summary["flown_s"] >= 7.9
    # the run's DDS domain is free again: a campaign's worker launches hundreds of runs
    from ima import dds
    assert run.result.domain is not None and run.result.domain not in dds._held
    assert run.result.wall_s >= 8.0
    assert run.summary["membership"] == ["node1", "node2", "node3"]
    # the bus paces the quanta: it says how late it released them, and each node how long
    # after its wall-clock time each window started (a few hundred microseconds on this
    # machine; a loose bound here, the oracle's is 2 ms at the p99)
    bus = json.loads((run.run_dir / "canbus.json").read_text())
    assert 0 <= bus["release_late_max_us"] < 1e6 and bus["quanta_late"] >= 0, bus
    starts = run.records("node2.jsonl", "window_start")
    late = sorted(e["wall_late_ns"] for e in starts)
    assert len(late) == len(starts) > 100, starts[:3]
    assert 0 <= late[len(late) // 2] < 50_000_000, late[-5:]


def test_ctrl_c_stops_everything(tmp_path):
    run_dir = tmp_path / "interrupted"
    proc = subprocess.Popen([IMA, "launch", str(TRIPLEX), "--duration", "600", "--run-dir",
                             str(run_dir), "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        truth = run_dir / "truth.jsonl"
        if truth.exists() and truth.stat().st_size > 20000:
            break
        time.sleep(0.2)
    os.kill(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode in (130, -signal.SIGINT), err.decode()[-2000:]
    time.sleep(0.5)
    assert _run_pids(str(run_dir)) == {}, "processes left behind"
    summary = json.loads(out)
    assert 0 < summary["flown_s"] < 600 and summary["nodes"] == ["node1", "node2", "node3"]
    # the summary says the run was cut short, and when; so does summary.json
    assert summary["interrupted"] is True and summary["interrupted_at_s"] == summary["flown_s"]
    assert json.loads((run_dir / "summary.json").read_text())["interrupted"] is True
    assert summary["vote_status"] is not None  # the world recorded the run up to the stop
    # the world stopped first, at the end of a quantum, and ended the run through the bus:
    # every trace is complete up to the stop
    last = {name: json.loads((run_dir / name).read_text().splitlines()[-1])
            for name in ("world.jsonl", "can.jsonl", "node1.jsonl", "node2.jsonl",
                         "node3.jsonl")}
    assert last["world.jsonl"]["kind"] == "stop", last
    assert last["world.jsonl"]["reason"] == "interrupted", last
    assert last["can.jsonl"]["kind"] == "bus_stop", last
    for k in (1, 2, 3):
        assert last[f"node{k}.jsonl"]["kind"] == "module_stop", last
        assert last[f"node{k}.jsonl"]["reason"] == "bus_stop", last
    # and the recording holds the run up to the stop
    from mcap.reader import make_reader

    assert summary["recording"] == str(run_dir / "run.mcap")
    truth_end = json.loads((run_dir / "truth.jsonl").read_text().splitlines()[-1])["t_ns"]
    with open(run_dir / "run.mcap", "rb") as f:
        times = [m.log_time for _, _, m in make_reader(f).iter_messages(topics=["/world/truth"])]
    assert max(times) == truth_end


@pytest.mark.parametrize("args,message", [
    (["--kill-node", "node9@10"], "no node 'node9'"),
    (["--kill-node", "node2"], "NODE@SECONDS"),
    (["--kill-node", "node2@900"], "after the end"),
    (["--hang-node", "node2@x"], "--hang-node wants NODE@SECONDS"),
    (["--hang-node", "node7@10"], "no node 'node7'"),
    (["--hang-node", "node2@10", "--kill-node", "node2@20"], "either killed or hung"),
    (["--test-wrong-output", "node2@5:yaw=1"], "AXIS"),
])
def test_bad_options_are_clear_errors(args, message, tmp_path):
    proc = subprocess.run([IMA, "launch", str(TRIPLEX), "--duration", "600",
                           "--run-dir", str(tmp_path / "r"), *args],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode != 0
    assert message in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr


def test_missing_system_file_is_a_clear_error(tmp_path):
    proc = subprocess.run([IMA, "launch", str(tmp_path / "nope.yaml")], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode != 0 and "nope.yaml" in proc.stderr and "Traceback" not in proc.stderr


@pytest.mark.skipif(os.geteuid() != 0 or not Path("/usr/sbin/ip").exists() and not Path("/sbin/ip").exists(),
                    reason="network namespaces need root and iproute2")
def test_netns_puts_each_node_in_its_own_namespace(launches):
    def namespaces() -> set[str]:
        out = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True).stdout
        return {line.split()[0] for line in out.splitlines() if line.strip()}

    before = namespaces()
    seen: dict = {}
    run_dir = launches.base / "netns"

    def on_status(st: dict) -> None:
        if not seen and st.get("t_s", 0) > 5:
            seen["ns"] = namespaces() - before
            seen["pids"] = _run_pids(str(run_dir))
            node_ns = seen["node_ns"] = {}
            for pid, cmd in seen["pids"].items():
                if "ima-dds-node" in cmd or "ima-ske" in cmd:
                    try:
                        node_ns[pid] = os.readlink(f"/proc/{pid}/ns/net")
                    except OSError:
                        pass

    run = launches.launch("netns", duration_s=20.0, seed=SEED, netns=True, on_status=on_status)
    assert len(seen["ns"]) == 3, seen
    # the agents found each other across the bridge, and voting ran on three replicas
    for node in ("node1", "node2", "node3"):
        peers = run.summary["dds"][node]["peers"]
        assert all(p["discovered"] and p["alive"] for p in peers), peers
    assert run.summary["vote_status"] == "MID3" and run.summary["voted_out"] == []
    # each node's processes were in a namespace of their own
    own = {os.readlink("/proc/self/ns/net")}
    node_ns = set(seen["node_ns"].values())
    assert len(seen["node_ns"]) == 6 and len(node_ns) == 3 and not node_ns & own, seen
    assert namespaces() == before, "namespaces left behind"
