# SPDX-License-Identifier: Apache-2.0
"""Starts, watches and stops the processes of a run: each in its own process group, ended by
SIGTERM then SIGKILL so that nothing outlives the run; the bus socket and its clients; the
watch that ends a run when a process fails (except a node the run stops on purpose)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from collections.abc import Callable
from pathlib import Path

from ima.errors import ImaError

_PR_SET_PDEATHSIG = 1
# A child that outlives the end of the run by this much (wall seconds) is killed.
GRACE_S = 10.0


def _preexec() -> None:
    """In the child before exec: SIGTERM if ima dies."""
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):
        pass


def tail(path: Path, lines: int = 5) -> str:
    """The last lines of a log, on one line."""
    try:
        text = path.read_text(errors="replace").strip().splitlines()
    except OSError:
        return "(no log)"
    return " | ".join(text[-lines:]) or "(empty log)"


def log_name(name: str) -> str:
    """The log file of a process: node2/dds -> node2-dds.log."""
    return name.replace("/", "-") + ".log"


def frozen(pid: int) -> bool:
    """Whether the process is stopped by a signal (state T in /proc/PID/stat)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rfind(")") + 2:][:1] == "T"


def _killpg(pgid: int, signum: int) -> None:
    try:
        os.killpg(pgid, signum)
    except ProcessLookupError:  # the whole group has ended
        pass


class Processes:
    """The run's child processes by name ("canbus", "world", "node2", "node2/dds")."""

    def __init__(self, run_dir: Path) -> None:
        self.run_dir = run_dir
        self.procs: dict[str, subprocess.Popen] = {}
        self.logs: list = []
        self.failed: dict[str, str] = {}  # processes that failed before the end, and why

    def start(self, name: str, cmd: list[str], env: dict[str, str] | None = None,
              stdout=None, cwd: Path | None = None,
              pass_fds: tuple[int, ...] = ()) -> subprocess.Popen:
        """Starts `cmd` with its standard error (and output, unless piped) in <name>.log;
        `pass_fds` are inherited (the launcher's channels)."""
        logf = open(self.run_dir / log_name(name), "wb")  # noqa: SIM115 - closed in close()
        self.logs.append(logf)
        try:
            proc = subprocess.Popen(
                cmd, stdout=stdout if stdout is not None else logf, stderr=logf,
                stdin=subprocess.DEVNULL, env=env, cwd=cwd, process_group=0,
                preexec_fn=_preexec, pass_fds=pass_fds,
            )
        except OSError as exc:
            raise ImaError(f"cannot start {cmd[0]}: {exc.strerror}") from exc
        self.procs[name] = proc
        return proc

    def log_tail(self, name: str, lines: int = 2) -> str:
        return tail(self.run_dir / log_name(name), lines)

    def kill_group(self, name: str, signum: int = signal.SIGKILL) -> None:
        proc = self.procs.get(name)
        if proc is not None and proc.poll() is None:
            _killpg(proc.pid, signum)

    def signal_all(self, signum: int) -> None:
        for name in self.procs:
            self.kill_group(name, signum)

    def wait_all(self, timeout: float, skip: Callable[[str], bool] = lambda name: False) -> None:
        deadline = time.monotonic() + timeout
        for name, proc in self.procs.items():
            if skip(name):
                continue
            try:
                proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass

    def stop(self) -> None:
        """SIGTERM, a grace period, then SIGKILL to whole groups: nothing is left behind.
        Every group is stopped first and continued last, so that each has its SIGTERM before
        any runs on: a DDS agent that sees another leave knows then that the run is ending
        (nodes/README.md), whichever of them the CPU takes first. A frozen process takes its
        SIGTERM at the SIGCONT too. Every group stopped is continued, its leader ended or
        not, whatever interrupts the SIGTERMs (Ctrl-C)."""
        stopped = []
        try:
            for proc in self.procs.values():
                if proc.poll() is None:
                    stopped.append(proc.pid)
                    _killpg(proc.pid, signal.SIGSTOP)
            for pid in stopped:
                _killpg(pid, signal.SIGTERM)
        finally:
            for pid in stopped:
                _killpg(pid, signal.SIGCONT)
        self.wait_all(5.0)
        self.signal_all(signal.SIGKILL)
        self.wait_all(5.0)

    def close(self) -> None:
        for f in self.logs:
            f.close()

    def returncodes(self) -> dict[str, int | None]:
        return {name: p.returncode for name, p in self.procs.items()}


# ---- the bus and its clients ---------------------------------------------------------------

def wait_for_socket(path: Path, procs: Processes, timeout: float = 10.0) -> None:
    """Waits until the bus listens on `path`."""
    bus = procs.procs["canbus"]
    deadline = time.monotonic() + timeout
    while not path.exists():
        if bus.poll() is not None:
            raise ImaError(f"ima-canbus exited ({bus.returncode}): {procs.log_tail('canbus', 5)}")
        if time.monotonic() > deadline:
            raise ImaError(f"ima-canbus did not open {path} within {timeout:.0f} s")
        time.sleep(0.005)


def bus_connections(sock: Path, pids: tuple[int, ...] = ()) -> int:
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


def wait_joined(sock: Path, count: int, procs: Processes, timeout: float = 10.0,
                pids: tuple[int, ...] = ()) -> None:
    """Waits until `count` clients are connected, so clients join in a fixed order (the bus
    numbers them by arrival, and the numbers are in its trace)."""
    deadline = time.monotonic() + timeout
    while bus_connections(sock, pids) < count:
        for name, proc in procs.procs.items():
            if proc.poll() is not None:
                raise ImaError(f"{name} exited ({proc.returncode}) before joining the bus: "
                               f"{procs.log_tail(name)}")
        if time.monotonic() > deadline:
            raise ImaError(f"fewer than {count} clients joined the bus within {timeout:.0f} s")
        time.sleep(0.002)


def wait_ready(agents: dict[str, subprocess.Popen], procs: Processes, timeout: float) -> None:
    """Every DDS agent prints `ready` once it has discovered the others."""
    deadline = time.monotonic() + timeout
    for name, proc in agents.items():
        assert proc.stdout is not None
        while True:
            if time.monotonic() > deadline:
                raise ImaError(f"{name} did not become ready within {timeout:.0f} s: "
                               f"{procs.log_tail(name, 3)}")
            line = proc.stdout.readline()
            if not line:
                raise ImaError(f"{name} exited ({proc.wait()}) before it was ready: "
                               f"{procs.log_tail(name, 3)}")
            if line.strip() == b"ready":
                break
        # whatever the agent prints later must not fill the pipe and stall it
        threading.Thread(target=_drain, args=(proc.stdout,), daemon=True).start()


def _drain(stream) -> None:
    for _ in stream:
        pass


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


class Watch:
    """Ends the run when a process fails before the end (the world would wait for its quanta
    for ever): the bus is told to end it (on its control channel), which stops the world. A
    node the run kills on purpose is not a failure: the rest of that node (its DDS agent) is
    killed too, as a dead processor's would be."""

    def __init__(self, procs: Processes, kills: dict[str, float],
                 stop_run: Callable[[], bool]) -> None:
        self.procs, self.kills = procs, kills
        self.stop_run = stop_run  # the bus's control channel: stopped_by "launcher"
        self.killed: dict[str, float] = {}
        self.stopping = threading.Event()  # Ctrl-C: the processes end because they are told to

    def settle(self) -> None:
        """Once every process has ended: a node the run killed (SIGKILL, from the bus) whose
        end this watch had no time to see, the run ending within its poll, is killed too, not
        failed."""
        for name, proc in self.procs.procs.items():
            if name in self.kills and name not in self.killed \
                    and proc.returncode == -signal.SIGKILL:
                self.killed[name] = self.kills[name]

    def _expected(self, name: str, code: int | None) -> str | None:
        """The node whose death this is, if it is one the run asked for."""
        node = name.split("/")[0]
        if node in self.kills and code not in (0, None):
            return node
        return None

    def __call__(self) -> None:
        procs = self.procs
        world = procs.procs["world"]
        while world.poll() is None:
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
                        for other in procs.procs:
                            if other.split("/")[0] == node:
                                procs.kill_group(other)
                    continue
                procs.failed[name] = f"exited with {code}: {procs.log_tail(name)}"
            if procs.failed:
                if bus is None or bus.poll() is not None or not self.stop_run():
                    world.terminate()
                return
            time.sleep(0.1)
