# SPDX-License-Identifier: Apache-2.0
"""Runs a system model: the CAN bus, one DDS agent and one SKE per node, and the world, in
lockstep, in a run directory.

The order is fixed so that the run is deterministic: the bus; every node's DDS agent (each
waits until it has discovered the others, then says `ready`); every node's SKE, joining the
bus in node order; the world (the last lockstep client, T=0 starts when it joins).

Files in the run directory, beyond those of `ima fly` (ima.flight.run):
  deploy/        the system deployed: one module per node, the C glue (ima deploy)
  nodeK.jsonl    node K's SKE trace (schedule, HM, partition reports: membership, monitor)
  ddsK.jsonl     node K's DDS agent trace (peers alive/lost, deadline misses; wall clock)
  ddsK.json      its statistics (samples, exchange latency)
  launch.json    how the run was started (system, domain ID, commands, kills, hangs)
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ima import paths
from ima.errors import ImaError
from ima.flight import run as flight

AXES = ("elev", "ail", "rud", "thr")
_READY_TIMEOUT_S = 60.0


@dataclass
class LaunchOptions:
    system: Path
    duration_s: float = 600.0
    seed: int = 1
    pilot: Path | None = None
    turbulence: str = "light"
    wind_kt: float = 10.0
    wind_from_deg: float = 270.0
    realtime: bool = False
    run_dir: Path | None = None
    kill: list[tuple[str, float]] = field(default_factory=list)  # (node, emulated s)
    hang: list[tuple[str, float]] = field(default_factory=list)  # (node, emulated s)
    # test-only: (node, axis, offset, from emulated s): that replica's command is wrong
    wrong_output: list[tuple[str, str, float, float]] = field(default_factory=list)
    netns: bool = False
    quantum_us: int = flight.DEFAULT_QUANTUM_US


@dataclass
class LaunchRun:
    run_dir: Path
    nodes: list[str]
    returncodes: dict[str, int]
    wall_s: float
    interrupted: bool
    killed: dict[str, float]  # node -> emulated time it was stopped at
    domain: int | None
    hung: dict[str, float] = field(default_factory=dict)  # node -> emulated time it froze at


def dds_agent_binary() -> Path:
    path = paths.build_dir() / "nodes" / "dds" / "ima-dds-node"
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise ImaError(f"ima-dds-node not built: run ./ima (it builds); expected {path}")
    return path


def parse_kill(text: str, option: str = "--kill-node") -> tuple[str, float]:
    """NODE@SECONDS, e.g. node2@120."""
    node, sep, when = text.partition("@")
    try:
        t = float(when)
    except ValueError:
        t = -1.0
    if not sep or not node or not t >= 0 or t == float("inf"):
        raise ImaError(f"{option} wants NODE@SECONDS (e.g. node2@120), not '{text}'")
    return node, t


def parse_wrong_output(text: str) -> tuple[str, str, float, float]:
    """NODE@SECONDS[:AXIS=OFFSET], e.g. node3@60:elev=0.3 (default elev=0.3)."""
    head, _, spec = text.partition(":")
    node, t = parse_kill(head, "--test-wrong-output")
    axis, value = "elev", 0.3
    if spec:
        axis, sep, val = spec.partition("=")
        try:
            value = float(val)
        except ValueError:
            sep = ""
        if not sep or axis not in AXES or value != value:
            raise ImaError(f"--test-wrong-output wants NODE@SECONDS[:AXIS=OFFSET] with AXIS one of "
                           f"{', '.join(AXES)}, not '{text}'")
    return node, axis, value, t


def _log(name: str) -> str:
    """The log file of a process: node2/dds -> node2-dds.log."""
    return name.replace("/", "-") + ".log"


def _frozen(pid: int) -> bool:
    """Whether the process is stopped by a signal (state T in /proc/PID/stat)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rfind(")") + 2:][:1] == "T"


class _NodeWatch:
    """Stops the run when a process fails, except a node the run kills on purpose: then the
    rest of that node (its DDS agent) is killed too, as a dead processor's would be."""

    def __init__(self, procs: flight._Procs, world: subprocess.Popen, run_dir: Path,
                 kills: dict[str, float]) -> None:
        self.procs, self.world, self.run_dir, self.kills = procs, world, run_dir, kills
        self.killed: dict[str, float] = {}
        self.stopping = threading.Event()  # Ctrl-C: the processes end because they are told to

    def _expected(self, name: str, code: int | None) -> str | None:
        """The node whose death this is, if it is one the run asked for."""
        node = name.split("/")[0]
        if node in self.kills and code not in (0, None):
            return node
        return None

    def __call__(self) -> None:
        procs = self.procs
        while self.world.poll() is None:
            bus = procs.procs.get("canbus")
            if self.stopping.is_set() or (bus is not None and bus.poll() is not None):
                return  # the run is ending: what exits now follows the bus
            for name, proc in list(procs.procs.items()):
                code = proc.poll()
                if name == "world" or code in (None, 0) or name in procs.failed:
                    continue
                node = self._expected(name, code)
                if node is not None:
                    if node not in self.killed:
                        self.killed[node] = self.kills[node]
                        for other, p in procs.procs.items():
                            if other.split("/")[0] == node and p.poll() is None:
                                try:
                                    os.killpg(p.pid, signal.SIGKILL)
                                except ProcessLookupError:
                                    pass
                    continue
                procs.failed[name] = (f"exited with {code}: "
                                      f"{flight._tail(self.run_dir / _log(name), 2)}")
            if procs.failed:
                bus = procs.procs.get("canbus")
                if bus is not None and bus.poll() is None:
                    bus.send_signal(signal.SIGTERM)
                else:
                    self.world.terminate()
                return
            time.sleep(0.1)


def _wait_ready(agents: dict[str, subprocess.Popen], run_dir: Path) -> None:
    """Every agent prints `ready` once it has discovered the others."""
    deadline = time.monotonic() + _READY_TIMEOUT_S
    for name, proc in agents.items():
        assert proc.stdout is not None
        while True:
            if time.monotonic() > deadline:
                raise ImaError(f"{name} did not become ready within {_READY_TIMEOUT_S:.0f} s: "
                               f"{flight._tail(run_dir / _log(name), 3)}")
            line = proc.stdout.readline()
            if not line:
                raise ImaError(f"{name} exited ({proc.wait()}) before it was ready: "
                               f"{flight._tail(run_dir / _log(name), 3)}")
            if line.strip() == b"ready":
                break
        # whatever the agent prints later must not fill the pipe and stall it
        threading.Thread(target=_drain, args=(proc.stdout,), daemon=True).start()


def _drain(stream) -> None:
    for _ in stream:
        pass


def launch(opts: LaunchOptions, on_status: Callable[[dict], None] | None = None) -> LaunchRun:
    """Runs the system to its end (or Ctrl-C); the caller summarises the run directory."""
    from ima import dds
    from ima.deploy import generate, load_system
    from imaworld import pilot as pilot_script

    if opts.turbulence not in flight.TURBULENCE:
        raise ImaError(f"--turbulence must be one of {', '.join(flight.TURBULENCE)}")
    if not opts.duration_s > 0:
        raise ImaError("--duration must be positive")
    system = load_system(Path(opts.system))
    names = [n.name for n in system.nodes]
    index = {n.name: n.index for n in system.nodes}
    kills: dict[str, float] = {}
    hangs: dict[str, float] = {}
    for option, faults, chosen in (("--kill-node", opts.kill, kills),
                                   ("--hang-node", opts.hang, hangs)):
        for node, t in faults:
            if node not in index:
                raise ImaError(f"{option} {node}@{t:g}: no node '{node}' in {system.path} "
                               f"(nodes: {', '.join(names)})")
            if t >= opts.duration_s:
                raise ImaError(f"{option} {node}@{t:g}: after the end of the run "
                               f"({opts.duration_s:g} s)")
            chosen[node] = min(t, chosen.get(node, t))
    both = sorted(set(kills) & set(hangs))
    if both:
        raise ImaError(f"{', '.join(both)}: a node is either killed or hung, not both")
    for node, _axis, _v, t in opts.wrong_output:
        if node not in index:
            raise ImaError(f"--test-wrong-output: no node '{node}' in {system.path}")
    if opts.netns and os.geteuid() != 0:
        raise ImaError("--netns needs root (it creates network namespaces)")
    pilot = Path(opts.pilot) if opts.pilot else flight.default_pilot()
    pilot_script.load(pilot)  # a bad script is reported before anything starts

    bus_bin = flight.canbus_binary()
    ske_bin = paths.ske_binary()
    n = len(names)
    agent_bin = dds_agent_binary() if n > 1 else None
    run_dir = Path(opts.run_dir) if opts.run_dir else flight.new_run_dir("launch", opts.seed)
    run_dir.mkdir(parents=True, exist_ok=True)
    deployed = generate(system, run_dir / "deploy")

    sock, sock_tmp = flight._socket_path(run_dir)
    sock_dir = sock.parent
    domain = dds.domain_for_run() if n > 1 else None
    dds_cfg = Path(system.dds["config"])
    voting = system.voting
    thresholds = ",".join(f"{float(voting['thresholds'][a]):g}" for a in AXES)
    persist = int(voting["persist"])
    misses = int(system.membership["missed_frames"])

    bus_cmd = [str(bus_bin), "--socket", str(sock), "--quantum-us", str(opts.quantum_us),
               "--bitrate", str(int(system.can["bitrate"])),
               "--lockstep-clients", str(1 + n), "--duration", f"{opts.duration_s:g}",
               "--trace", str(run_dir / "can.jsonl"), "--stats", str(run_dir / "canbus.json"), "-q"]
    for node, t in kills.items():
        bus_cmd += ["--kill-node", f"{index[node]}@{t:g}"]
    for node, t in hangs.items():
        bus_cmd += ["--hang-node", f"{index[node]}@{t:g}"]
    # Every node's io partition joins in the first quantum, all at once: fixed indices keep
    # the bus trace the same from run to run.
    bus_cmd += ["--client-order", ",".join([*names, "world", *(f"{n}/io" for n in names)])]
    if opts.realtime:
        bus_cmd.append("--realtime")
    world_cmd = [sys.executable, "-m", "imaworld", "--bus", str(sock), "--run-dir", str(run_dir),
                 "--seed", str(opts.seed), "--pilot", str(pilot), "--turbulence", opts.turbulence,
                 "--wind", f"{opts.wind_kt:g}", "--wind-from", f"{opts.wind_from_deg:g}",
                 "--channels", str(n), "--vote-threshold", thresholds,
                 "--vote-persist", str(persist), "--vote-offset", f"{float(voting['offset_s']):g}",
                 "--status"]
    partition_path = os.pathsep.join(
        p for p in (str(paths.build_dir() / "partitions"), os.environ.get("IMA_PARTITION_PATH")) if p)
    agent_cmds: dict[str, list[str]] = {}
    node_cmds: dict[str, list[str]] = {}
    node_env: dict[str, dict[str, str]] = {}
    for node in names:
        k = index[node]
        xch = sock_dir / f"xch{k}.sock"
        if agent_bin is not None:
            cmd = [str(agent_bin), "--node", str(k), "--nodes", str(n), "--socket", str(xch),
                   "--domain", str(domain), "--config", str(dds_cfg),
                   "--lease-ms", str(round(float(system.dds["liveliness_lease_s"]) * 1000)),
                   "--deadline-ms", str(round(float(system.dds["deadline_s"]) * 1000)),
                   "--trace", str(run_dir / f"dds{k}.jsonl"), "--stats", str(run_dir / f"dds{k}.json"),
                   "-q"]
            if opts.realtime:
                cmd.append("--realtime")
            agent_cmds[f"{node}/dds"] = cmd
        node_cmds[node] = [
            str(ske_bin), "--lockstep", str(sock), "--node", node, "--node-index", str(k),
            "--partition-path", partition_path,
            "--trace", str(run_dir / f"{node}.jsonl"), "--stats", str(run_dir / f"{node}.json"),
            "-q", str(deployed.modules[node])]
        env = {"IMA_NODE_INDEX": str(k), "IMA_NODES": str(n), "IMA_VOTE_THRESHOLDS": thresholds,
               "IMA_VOTE_PERSIST": str(persist), "IMA_MEMBERSHIP_MISSES": str(misses)}
        if agent_bin is not None:
            env["IMA_XCH"] = str(xch)
        for w_node, axis, value, t in opts.wrong_output:
            if w_node == node:
                env["IMA_TEST_CMD_BIAS"] = f"{axis}={value:g}@{t:g}"
        node_env[node] = env
    (run_dir / "launch.json").write_text(json.dumps({
        "kind": "launch", "system": str(system.path), "nodes": names, "seed": opts.seed,
        "duration_s": opts.duration_s, "pilot": str(pilot), "turbulence": opts.turbulence,
        "wind_kt": opts.wind_kt, "wind_from_deg": opts.wind_from_deg, "realtime": opts.realtime,
        "quantum_us": opts.quantum_us, "dds_domain": domain, "dds_config": str(dds_cfg),
        "kill": [{"node": k, "t_s": t} for k, t in kills.items()],
        "hang": [{"node": k, "t_s": t} for k, t in hangs.items()],
        "wrong_output": [{"node": a, "axis": b, "offset": c, "t_s": d}
                         for a, b, c, d in opts.wrong_output],
        "netns": opts.netns, "socket": str(sock),
        "modules": {k: str(v) for k, v in deployed.modules.items()},
        "environment": node_env,
        "commands": {"canbus": bus_cmd, "world": world_cmd, **agent_cmds, **node_cmds},
    }, indent=2) + "\n")

    procs = flight._Procs()
    interrupted = False
    t0 = time.monotonic()
    previous = {}
    watch: _NodeWatch | None = None
    hung: dict[str, float] = {}  # node -> emulated time the bus froze it
    netns = None

    def on_signal(signum: int, _frame: object) -> None:
        nonlocal interrupted
        interrupted = True
        if watch is not None:
            watch.stopping.set()
        bus = procs.procs.get("canbus")
        if bus is not None and bus.poll() is None:
            bus.send_signal(signal.SIGTERM)
        else:  # still starting: stop what has started
            procs.signal_all(signal.SIGTERM)

    try:
        for s in (signal.SIGINT, signal.SIGTERM):
            previous[s] = signal.signal(s, on_signal)
        if opts.netns:
            from ima.launch import netns as netns_mod

            netns = netns_mod.Namespaces(names, run_dir)
            netns.create()
        bus = procs.start("canbus", bus_cmd, run_dir / "canbus.log")
        flight._wait_for_socket(sock, bus, run_dir / "canbus.log")
        base_env = dict(os.environ, IMA_CANBUS=str(sock))
        agents = {}
        for name, cmd in agent_cmds.items():
            env = dict(base_env)
            node = name.split("/")[0]
            if netns is not None:
                cfg = netns.dds_config(node, run_dir)
                cmd = netns.wrap(node, [c if c != str(dds_cfg) else str(cfg) for c in cmd]
                                 + ["--bind-device", netns.device])
            agents[name] = procs.start(name, cmd, run_dir / _log(name),
                                       env=env, stdout=subprocess.PIPE)
        _wait_ready(agents, run_dir)
        netns_pids: list[int] = []
        for k, node in enumerate(names, start=1):
            cmd = node_cmds[node]
            if netns is not None:
                cmd = netns.wrap(node, cmd)
            proc = procs.start(node, cmd, run_dir / f"{node}.log",
                               env=dict(base_env, **node_env[node]))
            if netns is not None:
                netns_pids.append(proc.pid)
            flight._wait_joined(sock, k, procs, pids=tuple(netns_pids))
        world = procs.start("world", world_cmd, run_dir / "world.log", env=base_env,
                            stdout=subprocess.PIPE)
        watch = _NodeWatch(procs, world, run_dir, kills)
        threading.Thread(target=watch, daemon=True).start()
        flight.follow_world(world, on_status)
        # A hung processor is switched off at the end of the run: its frozen processes would
        # not even take a SIGTERM. Its agent ends with the others.
        for node in hangs:
            proc = procs.procs.get(node)
            if proc is not None and proc.poll() is None:
                if _frozen(proc.pid):  # the bus froze it: it never runs again
                    hung[node] = hangs[node]
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        deadline = time.monotonic() + flight._GRACE_S
        for name, proc in procs.procs.items():
            if name.endswith("/dds"):
                continue  # the agents end on SIGTERM below, after the nodes
            try:
                proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
    finally:
        procs.stop()
        procs.close()
        if netns is not None:
            netns.destroy()
        for s, h in previous.items():
            signal.signal(s, h)
        if sock_tmp is not None:
            shutil.rmtree(sock_tmp, ignore_errors=True)
        for node in names:
            try:
                (sock_dir / f"xch{index[node]}.sock").unlink()
            except OSError:
                pass
    wall = time.monotonic() - t0
    codes = {name: p.returncode for name, p in procs.procs.items()}
    if procs.failed:
        raise ImaError("the run stopped early: " + "; ".join(
            f"{k} {v}" for k, v in procs.failed.items()) + f" (run directory {run_dir})")
    killed = dict(watch.killed) if watch is not None else {}
    return LaunchRun(run_dir=run_dir, nodes=names, returncodes=codes, wall_s=wall,
                     interrupted=interrupted, killed=killed, domain=domain, hung=hung)

