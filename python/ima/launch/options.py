# SPDX-License-Identifier: Apache-2.0
"""What a run is asked to do (`ima launch`, `ima fly`, `ima demo`): the system, the flight,
the faults; where it runs (its run directory and socket directory)."""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from ima import paths
from ima.errors import ImaError

AXES = ("elev", "ail", "rud", "thr")
TURBULENCE = ("none", "light", "moderate")
DEFAULT_QUANTUM_US = 10000
# Unix socket addresses hold 107 bytes and a NUL; a run's sockets live in its directory when
# their paths fit.
_SOCKET_PATH_MAX = 100


@dataclass
class LaunchOptions:
    system: Path
    duration_s: float = 600.0
    seed: int = 1
    pilot: Path | None = None  # default: sim/pilots/default.yaml (fly_mission.yaml with a mission)
    # a mission plan (config/missions/*.yaml): uplinked over C2 at MISSION_UPLINK_S and flown
    mission: Path | None = None
    # plans uplinked later, replacing the one flown: [(emulated s, plan)]
    replan: list[tuple[float, Path]] = field(default_factory=list)
    turbulence: str = "light"
    wind_kt: float = 10.0
    wind_from_deg: float = 270.0
    realtime: bool = False
    # lockstep, but no faster than `speed` emulated seconds per wall second (None: as fast as
    # possible; --live: 1)
    speed: float | None = None
    live: bool = False  # serve the run over the Foxglove WebSocket protocol (ima.websocket)
    live_port: int = 8765
    run_dir: Path | None = None  # default: runs/<kind>-<date>-<time>-seed<N>
    kind: str = "launch"  # the run directory's prefix: launch, fly, demo
    kill: list[tuple[str, float]] = field(default_factory=list)  # (node, emulated s)
    hang: list[tuple[str, float]] = field(default_factory=list)  # (node, emulated s)
    # test-only: (node, axis, offset, from emulated s): that replica's command is wrong
    wrong_output: list[tuple[str, str, float, float]] = field(default_factory=list)
    netns: bool = False
    quantum_us: int = DEFAULT_QUANTUM_US
    # folders searched for the partition programs before the build's (a scratch build)
    partition_path: list[Path] = field(default_factory=list)
    # faultinject.Fault: --fault / --faults (the older options above are folded in)
    faults: list = field(default_factory=list)
    # with faults: fly the golden run too (same run without faults) and judge the run
    # against it with the oracles (faultinject.judge); `golden` reuses a golden run
    judge: bool = True
    golden: Path | None = None
    port_hashes: bool = False  # the SKEs trace a hash of every port message (data isolation)
    # test-only switches that plant a violation an oracle must see: "ske:NAME[=VALUE]" (every
    # node's SKE), "ske@NODE:NAME[=VALUE]" (one node's), "world:NAME[=VALUE]"
    test_switches: list[str] = field(default_factory=list)
    # DDS Security mode (ima.dds.security.MODES); None: the system model's channels.dds.security
    dds_security: str | None = None


@dataclass
class LaunchRun:
    run_dir: Path
    nodes: list[str]
    returncodes: dict[str, int | None]
    wall_s: float
    interrupted: bool
    killed: dict[str, float]  # node -> emulated time it was stopped at
    domain: int | None
    hung: dict[str, float] = field(default_factory=dict)  # node -> emulated time it froze at
    plan: object = None  # faultinject.plan.Plan of the run's faults (None without faults)


# When the station uplinks the mission plan: every node is up and flying by then.
MISSION_UPLINK_S = 2.0


def default_pilot(mission: bool = False) -> Path:
    """The remote pilot's script: the autopilot's, or with a mission plan the one that hands
    the aircraft to the mission manager."""
    name = "fly_mission.yaml" if mission else "default.yaml"
    return paths.repo_root() / "sim" / "pilots" / name


def system_path(name: str) -> Path:
    """A shipped system model: config/systems/<name>.yaml."""
    return paths.repo_root() / "config" / "systems" / f"{name}.yaml"


def binary(relative: str) -> Path:
    """A program of the C build, e.g. nodes/ima-canbus."""
    path = paths.build_dir() / relative
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise ImaError(f"{path.name} not built: run ./ima (it builds); expected {path}")
    return path


def new_run_dir(kind: str, seed: int) -> Path:
    """runs/<kind>-<date>-<time>-seed<N>[-k]: one folder per run, never reused."""
    base = paths.repo_root() / "runs"
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for k in range(1000):
        path = base / (f"{kind}-{stamp}-seed{seed}" + (f"-{k}" if k else ""))
        try:
            path.mkdir(parents=True)
            return path
        except FileExistsError:
            continue
    raise ImaError(f"cannot make a run directory under {base}")


def socket_dir(run_dir: Path) -> tuple[Path, Path | None]:
    """The directory of the run's Unix sockets: a fresh one of its own in the temporary folder,
    which only the run's owner may enter (0700: nobody else can reach the bus or the agents),
    returned twice (the second to remove at the end). Every node's ima-ske runs in it, so the
    module's socket paths are relative to it; RUN_DIR/can.sock links to the bus's socket for
    the tools that watch a run (the link leads nobody else in)."""
    tmp = Path(tempfile.mkdtemp(prefix="ima-run-"))
    os.chmod(tmp, 0o700)
    return tmp, tmp


def parse_node_at(text: str, option: str = "--kill-node") -> tuple[str, float]:
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
    node, t = parse_node_at(head, "--test-wrong-output")
    axis, value = "elev", 0.3
    if spec:
        axis, sep, val = spec.partition("=")
        try:
            value = float(val)
        except ValueError:
            sep = ""
        if not sep or axis not in AXES or value != value or value in (float("inf"), float("-inf")):
            raise ImaError(f"--test-wrong-output wants NODE@SECONDS[:AXIS=OFFSET] with AXIS one of "
                           f"{', '.join(AXES)}, not '{text}'")
    return node, axis, value, t
