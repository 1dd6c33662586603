# SPDX-License-Identifier: Apache-2.0
"""Starting and stopping the nodes' DDS agents (ima-dds-node) of a run."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from ima import paths
from ima.dds import config_path, dds_env, domain_lock_fd
from ima.errors import ImaError


def agent_binary() -> Path:
    path = paths.build_dir() / "nodes" / "dds" / "ima-dds-node"
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise ImaError(f"ima-dds-node not built: run `cmake --build {paths.build_dir()}`; "
                       f"expected {path}")
    return path


@dataclass
class Agent:
    """One running agent: its process and where it writes."""

    node: int
    socket: Path
    proc: subprocess.Popen
    trace: Path | None = None
    stats: Path | None = None
    stderr: Path | None = None
    args: list[str] = field(default_factory=list)

    @property
    def pid(self) -> int:
        return self.proc.pid

    def wait_ready(self, timeout: float = 30.0) -> None:
        """Waits for the agent's `ready` line (it prints it once it found the other agents)."""
        end = time.monotonic() + timeout
        line = b""
        fd = self.proc.stdout.fileno()
        while not line.endswith(b"\n"):
            left = end - time.monotonic()
            if left <= 0:
                raise ImaError(f"node{self.node}'s DDS agent not ready after {timeout:g} s")
            r, _, _ = select.select([fd], [], [], left)
            if r:
                chunk = os.read(fd, 1)
                if not chunk:
                    raise ImaError(f"node{self.node}'s DDS agent exited before it was ready "
                                   f"(status {self.proc.wait()}): {self.stderr_text()}")
                line += chunk
        if line.strip() != b"ready":
            raise ImaError(f"node{self.node}'s DDS agent said {line!r} instead of ready")

    def stop(self, timeout: float = 10.0) -> int:
        """SIGTERM, then SIGKILL if it does not exit in time; returns the exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self.proc.stdout:
            self.proc.stdout.close()
        return self.proc.returncode

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()

    def events(self) -> list[dict]:
        if not self.trace or not self.trace.exists():
            return []
        return [json.loads(line) for line in self.trace.read_text().splitlines() if line]

    def of_kind(self, kind: str, **match) -> list[dict]:
        return [e for e in self.events() if e["kind"] == kind
                and all(e.get(k) == v for k, v in match.items())]

    def read_stats(self) -> dict | None:
        if self.stats and self.stats.exists():
            return json.loads(self.stats.read_text())
        return None

    def stderr_text(self) -> str:
        return self.stderr.read_text() if self.stderr and self.stderr.exists() else ""


def _security_dir(security, run_dir: Path, nodes: int, domain: int) -> Path | None:
    """The DDS Security files for the agent: those of a Material, or of `security` mode made
    in run_dir once (None for "off")."""
    from ima.dds import security as sec

    if isinstance(security, sec.Material):
        return security.dir
    if security == "off":
        return None
    if sec.mode_of(run_dir / sec.DIR_NAME) != security:
        sec.prepare(run_dir, nodes, domain, security)
    return run_dir / sec.DIR_NAME


def start_agent(node: int, nodes: int, run_dir: Path, domain: int, *, realtime: bool = False,
                extra: list[str] | tuple = (), wait: bool = False,
                security="sign", fds: tuple[int, ...] = ()) -> Agent:
    """Starts node's agent with its socket, trace, statistics and stderr in run_dir; `fds`
    are inherited (e.g. --ske-pid-fd's). `security`: a DDS Security mode
    (ima.dds.security.MODES; the files are made in run_dir) or the Material of a run; "off"
    for none (a Python cyclonedds participant can then talk to the agent: it has no security
    plugins)."""
    run_dir = Path(run_dir)
    sock = run_dir / f"xch{node}.sock"
    trace = run_dir / f"dds{node}.jsonl"
    stats = run_dir / f"dds{node}.stats.json"
    err = run_dir / f"dds{node}.stderr"
    args = [str(agent_binary()), "--node", str(node), "--nodes", str(nodes), "--socket",
            str(sock), "--domain", str(domain), "--config", str(config_path()),
            "--trace", str(trace), "--stats", str(stats), "-q"]
    if realtime:
        args.append("--realtime")
    sec_dir = _security_dir(security, run_dir, nodes, domain)
    if sec_dir is not None:
        args += ["--security", str(sec_dir)]
    args += [str(a) for a in extra]
    try:
        pass_fds = (domain_lock_fd(domain), *fds)
    except ImaError:
        pass_fds = tuple(fds)
    with open(err, "wb") as errf:
        proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=errf, env=dds_env(), pass_fds=pass_fds)
    a = Agent(node, sock, proc, trace, stats, err, args)
    if wait:
        a.wait_ready()
    return a


def start_agents(nodes: int, run_dir: Path, domain: int, **kw) -> list[Agent]:
    """Starts the agents of nodes 1..nodes and waits until each is ready."""
    agents = [start_agent(k, nodes, run_dir, domain, **kw) for k in range(1, nodes + 1)]
    try:
        for a in agents:
            a.wait_ready()
    except BaseException:
        for a in agents:
            a.kill()
        raise
    return agents
