# SPDX-License-Identifier: Apache-2.0
"""The command lines of a run's processes, from the deployed system and the options: the CAN
bus, the world, each node's DDS agent (with more than one node) and each node's ima-ske. What
the partitions need reaches them through their node's module, never through the environment."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

from faultinject.plan import Plan
from ima import paths
from ima.deploy import System
from ima.deploy.model import VOTING_AXES, canbus_socket_name, dds_socket_name
from ima.errors import ImaError
from ima.launch.options import MISSION_UPLINK_S, LaunchOptions, binary


@dataclass
class RunPlan:
    """Everything a run starts, in the order it starts it."""

    sock_dir: Path  # every node's ima-ske runs here: the modules' socket paths are relative
    bus: list[str]
    world: list[str]
    agents: dict[str, list[str]] = field(default_factory=dict)  # "node2/dds" -> command
    nodes: dict[str, list[str]] = field(default_factory=dict)  # "node2" -> command

    @property
    def bus_socket(self) -> Path:
        return self.sock_dir / canbus_socket_name()


def partition_path(first: list[Path]) -> str:
    """Where the nodes find the partition programs: `first`, the build's, $IMA_PARTITION_PATH."""
    return os.pathsep.join(p for p in (*map(str, first), str(paths.build_dir() / "partitions"),
                                       os.environ.get("IMA_PARTITION_PATH")) if p)


def plan(system: System, opts: LaunchOptions, run_dir: Path, sock_dir: Path, pilot: Path,
         modules: dict[str, Path], faults: Plan, domain: int | None,
         security: Path | None = None) -> RunPlan:
    """The command lines; `faults` gives the injectors' words (faultinject.plan); `security`:
    the run's DDS Security files (ima.dds.security), None without."""
    names = [n.name for n in system.nodes]
    index = {n.name: n.index for n in system.nodes}
    n = len(names)
    sock = sock_dir / canbus_socket_name()
    bus = [str(binary("nodes/ima-canbus")), "--socket", str(sock),
           "--quantum-us", str(opts.quantum_us), "--bitrate", str(int(system.can["bitrate"])),
           "--lockstep-clients", str(1 + n), "--duration", f"{opts.duration_s:g}",
           "--trace", str(run_dir / "can.jsonl"), "--stats", str(run_dir / "canbus.json"), "-q"]
    for node, t in faults.kills.items():
        bus += ["--kill-node", f"{index[node]}@{t:g}"]
    for node, t in faults.hangs.items():
        bus += ["--hang-node", f"{index[node]}@{t:g}"]
    bus += faults.bus
    # Every node's io partition joins in the first quantum, all at once: fixed indices keep
    # the bus trace the same from run to run.
    bus += ["--client-order", ",".join([*names, "world", *(f"{x}/io" for x in names)])]
    bus += declared_clients(names, index)
    if opts.realtime:
        bus.append("--realtime")
    elif opts.speed is not None or opts.live:
        bus += ["--pace", f"{opts.speed or 1.0:g}"]

    world = [sys.executable, "-m", "imaworld", "--bus", str(sock), "--run-dir", str(run_dir),
             "--seed", str(opts.seed), "--pilot", str(pilot), "--turbulence", opts.turbulence,
             "--wind", f"{opts.wind_kt:g}", "--wind-from", f"{opts.wind_from_deg:g}", "--status"]
    if system.replicated and n > 1:
        # The smart actuators vote over the replicas; one replica has nothing to vote against.
        v = system.voting
        thresholds = ",".join(f"{float(v['thresholds'][a]):g}" for a in VOTING_AXES)
        world += ["--channels", str(n), "--vote-threshold", thresholds,
                  "--vote-persist", str(int(v["persist"])),
                  "--vote-offset", f"{float(v['offset_s']):g}",
                  "--vote-period", f"{system.major_frame_s:g}"]
    if opts.mission is not None:
        world += ["--uplink", f"{MISSION_UPLINK_S:g}:{run_dir / 'mission.img'}"]
        for k, (t, _) in enumerate(opts.replan, start=1):
            world += ["--uplink", f"{t:g}:{run_dir / f'mission-{k}.img'}"]
    world += faults.world
    switches = test_switches(opts.test_switches, names)
    world += switches.get("world", [])
    out = RunPlan(sock_dir=sock_dir, bus=bus, world=world)

    for node in names:
        k = index[node]
        if n > 1:
            cmd = [str(binary("nodes/dds/ima-dds-node")), "--node", str(k), "--nodes", str(n),
                   "--socket", str(sock_dir / dds_socket_name(k)), "--domain", str(domain),
                   "--config", str(system.dds["config"]),
                   "--lease-ms", str(round(float(system.dds["liveliness_lease_s"]) * 1000)),
                   "--deadline-ms", str(round(float(system.dds["deadline_s"]) * 1000)),
                   "--trace", str(run_dir / f"dds{k}.jsonl"),
                   "--stats", str(run_dir / f"dds{k}.json"), "-q"]
            if opts.realtime:
                cmd.append("--realtime")
            if security is not None:
                cmd += ["--security", str(security)]
            out.agents[f"{node}/dds"] = cmd + faults.dds.get(node, [])
        out.nodes[node] = [
            str(paths.ske_binary()), "--lockstep", str(sock), "--node", node,
            "--node-index", str(k), "--partition-path", partition_path(opts.partition_path),
            "--trace", str(run_dir / f"{node}.jsonl"), "--stats", str(run_dir / f"{node}.json"),
            "--output-dir", str(run_dir),  # the partitions' output files (the recordings)
            "-q", *(["--trace-port-hashes"] if opts.port_hashes else []),
            *faults.ske.get(node, []), *switches.get(node, []), "--", str(modules[node])]
    return out


def declared_clients(names: list[str], index: dict[str, int]) -> list[str]:
    """The bus's --client words: every client of the run as its hello will say (nodes/README.md,
    "Who may join"); another name joins listen-only, a second one of these names is refused."""
    out = ["--client", "world:can+lockstep:0"]
    for node in names:
        out += ["--client", f"{node}:lockstep:{index[node]}",
                "--client", f"{node}/io:can:{index[node]}"]
    return out


def test_switches(texts: list[str], nodes: list[str]) -> dict[str, list[str]]:
    """Test-only switches ("ske:NAME", "ske@node2:NAME", "world:NAME") as the words of each
    component: node name or "world" -> ["--test-switch", NAME, ...]."""
    out: dict[str, list[str]] = {}
    for text in texts:
        where, sep, name = text.partition(":")
        comp, _, node = where.partition("@")
        if not sep or not name or comp not in ("ske", "world") or (node and node not in nodes):
            raise ImaError(f"--test-switch {text!r}: expected ske:NAME, ske@NODE:NAME or "
                           "world:NAME")
        for target in ([node] if node else nodes) if comp == "ske" else ["world"]:
            out.setdefault(target, []).extend(["--test-switch", name])
    return out
