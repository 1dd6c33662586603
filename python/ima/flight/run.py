# SPDX-License-Identifier: Apache-2.0
"""Runs one flight: the CAN bus, the world (JSBSim) and the node(s), in lockstep, in a run dir.

Processes and their files in the run directory:
  ima-canbus   can.jsonl (every frame), canbus.json (statistics), canbus.log (stderr)
  ima-ske      node1.jsonl (schedule, HM, partition reports), node1.json, node1.log
  world        truth.jsonl (the aircraft's true state), world.jsonl, world.json, world.log
  this module  run.json (how it was started), summary.json (written by ima.flight.summary)
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ima import paths
from ima.errors import ImaError

DEFAULT_QUANTUM_US = 10000
NODE_MODULE = "rpas_node.xml"
TURBULENCE = ("none", "light", "moderate")
# A child that outlives the end of the run by this much (wall seconds) is killed.
_GRACE_S = 10.0
_PR_SET_PDEATHSIG = 1


@dataclass
class FlightOptions:
    duration_s: float = 600.0
    seed: int = 1
    pilot: Path | None = None  # default: sim/pilots/default.yaml
    turbulence: str = "light"
    wind_kt: float = 10.0
    wind_from_deg: float = 270.0
    realtime: bool = False
    run_dir: Path | None = None
    node_module: Path | None = None  # default: config/nodes/rpas_node.xml
    quantum_us: int = DEFAULT_QUANTUM_US
    nodes: int = 1


@dataclass
class FlightRun:
    run_dir: Path
    returncodes: dict[str, int]
    wall_s: float
    interrupted: bool


def default_pilot() -> Path:
    return paths.repo_root() / "sim" / "pilots" / "default.yaml"


def default_node_module() -> Path:
    return paths.repo_root() / "config" / "nodes" / NODE_MODULE


def canbus_binary() -> Path:
    path = paths.build_dir() / "nodes" / "ima-canbus"
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise ImaError(f"ima-canbus not built: run ./ima (it builds); expected {path}")
    return path


def new_run_dir(kind: str, seed: int) -> Path:
    """runs/<kind>-<date>-<time>-seed<N>[-k]: one folder per run, never reused."""
    base = paths.repo_root() / "runs"
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for k in range(1000):
        path = base / f"{kind}-{stamp}-seed{seed}" if k == 0 else base / f"{kind}-{stamp}-seed{seed}-{k}"
        try:
            path.mkdir(parents=True)
            return path
        except FileExistsError:
            continue
    raise ImaError(f"cannot make a run directory under {base}")


def _preexec() -> None:
    """In the child before exec: its own process group, and SIGTERM if ima dies."""
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):
        pass


def _socket_path(run_dir: Path) -> tuple[Path, Path | None]:
    """The bus socket: in the run directory when its path fits a Unix socket address."""
    path = run_dir / "can.sock"
    if len(os.fsencode(path)) < 100:
        return path, None
    tmp = Path(tempfile.mkdtemp(prefix="ima-bus-"))
    return tmp / "can.sock", tmp


class _Procs:
    """The run's child processes, each in its own process group, stopped together."""

    def __init__(self) -> None:
        self.procs: dict[str, subprocess.Popen] = {}
        self.logs: list = []
        self.failed: dict[str, str] = {}  # processes that failed before the end, and why

    def start(self, name: str, cmd: list[str], log: Path, env: dict[str, str] | None = None,
              stdout=None) -> subprocess.Popen:
        logf = open(log, "wb")  # noqa: SIM115 - closed in close()
        self.logs.append(logf)
        try:
            proc = subprocess.Popen(
                cmd, stdout=stdout if stdout is not None else logf, stderr=logf,
                stdin=subprocess.DEVNULL, env=env, process_group=0, preexec_fn=_preexec,
            )
        except OSError as exc:
            raise ImaError(f"cannot start {cmd[0]}: {exc.strerror}") from exc
        self.procs[name] = proc
        return proc

    def signal_all(self, signum: int) -> None:
        for proc in self.procs.values():
            if proc.poll() is None:
                try:
                    os.killpg(proc.pid, signum)
                except ProcessLookupError:
                    pass

    def wait_all(self, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        for proc in self.procs.values():
            left = max(0.0, deadline - time.monotonic())
            try:
                proc.wait(timeout=left)
            except subprocess.TimeoutExpired:
                pass

    def stop(self) -> None:
        """SIGTERM, a grace period, then SIGKILL to whole groups: nothing is left behind."""
        self.signal_all(signal.SIGTERM)
        self.signal_all(signal.SIGCONT)  # a frozen process takes its SIGTERM now
        self.wait_all(5.0)
        self.signal_all(signal.SIGKILL)
        self.wait_all(5.0)

    def close(self) -> None:
        for f in self.logs:
            f.close()


def _wait_for_socket(path: Path, bus: subprocess.Popen, log: Path, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists():
        if bus.poll() is not None:
            raise ImaError(f"ima-canbus exited ({bus.returncode}): {_tail(log)}")
        if time.monotonic() > deadline:
            raise ImaError(f"ima-canbus did not open {path} within {timeout:.0f} s")
        time.sleep(0.005)


def _bus_connections(sock: Path, pids: tuple[int, ...] = ()) -> int:
    """Connections made to the bus on `sock` (their bus side appears in /proc/net/unix under
    its path as soon as the client has connected, accepted or not). A client in another
    network namespace has its connection listed in that namespace's table: `pids` are
    processes whose namespaces to read too."""
    name = os.fsencode(sock)
    inodes = set()
    for table in ("/proc/net/unix", *(f"/proc/{pid}/net/unix" for pid in pids)):
        try:
            with open(table, "rb") as f:
                lines = f.read().splitlines()[1:]
        except OSError:
            continue
        # the listening socket has flag __SO_ACCEPTCON (00010000); accepted ones do not
        inodes.update(ln.split()[6] for ln in lines
                      if ln.endswith(b" " + name) and ln.split()[3] != b"00010000")
    return len(inodes)


def _wait_joined(sock: Path, count: int, procs: _Procs, timeout: float = 10.0,
                 pids: tuple[int, ...] = ()) -> None:
    """Waits until `count` clients are connected, so clients join in a fixed order (the bus
    numbers them by arrival, and the numbers are in its trace)."""
    deadline = time.monotonic() + timeout
    while _bus_connections(sock, pids) < count:
        for name, proc in procs.procs.items():
            if proc.poll() is not None:
                raise ImaError(f"{name} exited ({proc.returncode}) before joining the bus")
        if time.monotonic() > deadline:
            raise ImaError(f"fewer than {count} clients joined the bus within {timeout:.0f} s")
        time.sleep(0.002)


def _tail(path: Path, lines: int = 5) -> str:
    try:
        text = path.read_text(errors="replace").strip().splitlines()
    except OSError:
        return "(no log)"
    return " | ".join(text[-lines:]) or "(empty log)"


def _watch(procs: _Procs, world: subprocess.Popen, run_dir: Path) -> None:
    """A node or the bus that fails before the end stops the run (the world would wait for
    its quanta forever): the bus is told to end it, which stops the world."""
    while world.poll() is None:
        for name, proc in procs.procs.items():
            if name != "world" and proc.poll() not in (None, 0):
                procs.failed.setdefault(name, f"exited with {proc.returncode}: "
                                        f"{_tail(run_dir / f'{name}.log', 2)}")
        if procs.failed:
            bus = procs.procs.get("canbus")
            if bus is not None and bus.poll() is None:
                bus.send_signal(signal.SIGTERM)
            else:
                world.terminate()
            return
        time.sleep(0.2)


def follow_world(world: subprocess.Popen, on_status: Callable[[dict], None] | None) -> None:
    """Passes the world's status lines (JSON objects on its stdout) on until it exits."""
    assert world.stdout is not None
    for line in world.stdout:
        if on_status is None:
            continue
        try:
            status = json.loads(line)
        except ValueError:
            continue
        if isinstance(status, dict):
            on_status(status)
    world.wait()


def fly(opts: FlightOptions, on_status: Callable[[dict], None] | None = None) -> FlightRun:
    """Runs the flight to its end (or Ctrl-C); the caller summarises the run directory."""
    if opts.turbulence not in TURBULENCE:
        raise ImaError(f"--turbulence must be one of {', '.join(TURBULENCE)}")
    if not opts.duration_s > 0:
        raise ImaError("--duration must be positive")
    pilot = Path(opts.pilot) if opts.pilot else default_pilot()
    from imaworld import pilot as pilot_script

    pilot_script.load(pilot)  # a bad script is reported here, before anything starts
    module = Path(opts.node_module) if opts.node_module else default_node_module()
    if not module.is_file():
        raise ImaError(f"node module not found: {module}")
    bus_bin = canbus_binary()
    ske_bin = paths.ske_binary()
    run_dir = Path(opts.run_dir) if opts.run_dir else new_run_dir("fly", opts.seed)
    run_dir.mkdir(parents=True, exist_ok=True)
    sock, sock_tmp = _socket_path(run_dir)

    bus_cmd = [str(bus_bin), "--socket", str(sock), "--quantum-us", str(opts.quantum_us),
               "--lockstep-clients", str(1 + opts.nodes), "--duration", f"{opts.duration_s:g}",
               "--trace", str(run_dir / "can.jsonl"), "--stats", str(run_dir / "canbus.json"), "-q"]
    if opts.realtime:
        bus_cmd.append("--realtime")
    world_cmd = [sys.executable, "-m", "imaworld", "--bus", str(sock), "--run-dir", str(run_dir),
                 "--seed", str(opts.seed), "--pilot", str(pilot), "--turbulence", opts.turbulence,
                 "--wind", f"{opts.wind_kt:g}", "--wind-from", f"{opts.wind_from_deg:g}", "--status"]
    partition_path = os.pathsep.join(
        p for p in (str(paths.build_dir() / "partitions"), os.environ.get("IMA_PARTITION_PATH")) if p)
    node_cmds = []
    for k in range(1, opts.nodes + 1):
        node_cmds.append((f"node{k}", [
            str(ske_bin), "--lockstep", str(sock), "--node", f"node{k}", "--node-index", str(k),
            "--partition-path", partition_path,
            "--trace", str(run_dir / f"node{k}.jsonl"), "--stats", str(run_dir / f"node{k}.json"),
            "-q", str(module)]))
    (run_dir / "run.json").write_text(json.dumps({
        "kind": "fly", "seed": opts.seed, "duration_s": opts.duration_s, "pilot": str(pilot),
        "turbulence": opts.turbulence, "wind_kt": opts.wind_kt, "wind_from_deg": opts.wind_from_deg,
        "realtime": opts.realtime, "quantum_us": opts.quantum_us, "module": str(module),
        "nodes": opts.nodes, "socket": str(sock),
        "commands": {"canbus": bus_cmd, "world": world_cmd, **dict(node_cmds)},
    }, indent=2) + "\n")

    procs = _Procs()
    interrupted = False
    t0 = time.monotonic()
    previous = {}

    def on_signal(signum: int, _frame: object) -> None:
        nonlocal interrupted
        interrupted = True
        # The bus ends the run for everyone (STOP to each client); the rest follows.
        bus = procs.procs.get("canbus")
        if bus is not None and bus.poll() is None:
            bus.send_signal(signal.SIGTERM)

    try:
        for s in (signal.SIGINT, signal.SIGTERM):
            previous[s] = signal.signal(s, on_signal)
        bus = procs.start("canbus", bus_cmd, run_dir / "canbus.log")
        _wait_for_socket(sock, bus, run_dir / "canbus.log")
        base_env = dict(os.environ, IMA_CANBUS=str(sock))
        for k, (name, cmd) in enumerate(node_cmds, start=1):
            env = dict(base_env, IMA_NODE_INDEX=name.removeprefix("node"))
            procs.start(name, cmd, run_dir / f"{name}.log", env=env)
            _wait_joined(sock, k, procs)
        world = procs.start("world", world_cmd, run_dir / "world.log", env=base_env,
                            stdout=subprocess.PIPE)
        assert world.stdout is not None
        watchdog = threading.Thread(target=_watch, args=(procs, world, run_dir), daemon=True)
        watchdog.start()
        follow_world(world, on_status)
        # The world has stopped: the bus ends the run within a quantum; then the nodes.
        deadline = time.monotonic() + _GRACE_S
        for proc in procs.procs.values():
            try:
                proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
    finally:
        procs.stop()
        procs.close()
        for s, h in previous.items():
            signal.signal(s, h)
        if sock_tmp is not None:
            shutil.rmtree(sock_tmp, ignore_errors=True)
    wall = time.monotonic() - t0
    codes = {name: p.returncode for name, p in procs.procs.items()}
    if procs.failed:
        raise ImaError("the flight stopped early: " + "; ".join(
            f"{k} {v}" for k, v in procs.failed.items()) + f" (run directory {run_dir})")
    return FlightRun(run_dir=run_dir, returncodes=codes, wall_s=wall, interrupted=interrupted)
