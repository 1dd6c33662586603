# SPDX-License-Identifier: Apache-2.0
"""The system model: what config/systems/*.yaml holds, once loaded and checked."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from ima.errors import ImaError

NS_PER_S = 1_000_000_000

# Redundancy channel letter of node index 1..3 (ARINC 825 RCI 0..2).
CHANNEL_LETTERS = "ABC"

# The emulator's system states and error identifiers (docs/health-monitoring.md), with the
# descriptions the module's System_HM_Table carries.
HM_STATES = {
    "MODULE_INIT": (0, "module initialisation"),
    "PARTITION_INIT": (1, "partition initialisation"),
    "PROCESS": (2, "process execution"),
    "ERROR_HANDLER": (3, "error handler"),
}
HM_ERRORS = {
    "DEADLINE_MISSED": (1, "deadline missed"),
    "APPLICATION_ERROR": (2, "application error"),
    "NUMERIC_ERROR": (3, "numeric error"),
    "ILLEGAL_REQUEST": (4, "illegal request"),
    "STACK_OVERFLOW": (5, "stack overflow"),
    "MEMORY_VIOLATION": (6, "memory violation"),
    "HARDWARE_FAULT": (7, "hardware fault"),
    "POWER_FAIL": (8, "power failure"),
    "WINDOW_OVERRUN": (9, "window overrun"),
    "PARTITION_EXIT": (10, "partition process ended"),
}

VOTING_AXES = ("elev", "ail", "rud", "thr")

# What a partition's `arguments` may hold in braces, filled in per node by `ima deploy`:
# the settings that differ from node to node or come from the model reach a partition this
# way (its module's `ima:Linux Arguments`), so one program serves every node and every model.
ARGUMENT_FIELDS = {
    "node": "the node's name (node2)",
    "node_index": "the node's index 1..3",
    "node_channel": "its ARINC 825 redundancy channel letter A..C",
    "node_indices": "the indices of the system's nodes, 1,2,3",
    "canbus_socket": "the CAN bus socket, relative to the node's ima-ske working directory",
    "dds_socket": "the node's DDS agent socket, relative to the same directory",
    "vote_thresholds": "voting.thresholds as elev,ail,rud,thr",
    "vote_persist": "voting.persist",
    "membership_missed_frames": "membership.missed_frames",
}
_FIELD = re.compile(r"\{([^{}]*)\}")


def argument_fields(word: str) -> list[str]:
    """The {names} in an argument word."""
    return _FIELD.findall(word)


def canbus_socket_name() -> str:
    return "can.sock"


def dds_socket_name(index: int) -> str:
    return f"dds{index}.sock"


class SystemModelError(ImaError):
    """A system model that cannot be read or breaks a rule; the message names file, line, path."""

    def __init__(self, message: str) -> None:
        super().__init__(message, exit_code=2)


def seconds_text(ns: int) -> str:
    """Decimal seconds as the module XML writes them: 50000000 -> '0.05', 10**9 -> '1.0'."""
    whole, frac = divmod(ns, NS_PER_S)
    return f"{whole}.{f'{frac:09d}'.rstrip('0') or '0'}"


@dataclass(frozen=True)
class Node:
    """One processor. `index` 1..3 is its ARINC 825 redundancy channel A..C."""

    name: str
    index: int

    @property
    def channel(self) -> str:
        """The redundancy channel letter: 'A' for index 1."""
        return CHANNEL_LETTERS[self.index - 1]

    @property
    def rci(self) -> int:
        """The redundancy channel number in a CAN identifier's last two bits (A = 0)."""
        return self.index - 1


@dataclass
class Port:
    name: str
    direction: str  # "source" | "destination"
    kind: str  # "sampling" | "queuing"
    size: int
    refresh_ns: int | None = None  # sampling ports
    max_messages: int | None = None  # queuing ports
    message: str | None = None  # the C type of its messages (checked against `size`)

    @property
    def is_source(self) -> bool:
        return self.direction == "source"


@dataclass
class Process:
    name: str
    period_ns: int
    stack: int
    priority: int
    offset_ns: int = 0
    deadline: str = "soft"


@dataclass
class Memory:
    size: int
    type: str | None = None
    access: str | None = None


@dataclass
class Partition:
    ident: int
    name: str
    criticality: str
    system_partition: bool
    personality: str
    executable: str
    arguments: list[str]
    period_ns: int
    processes: list[Process]
    ports: list[Port]
    memory: list[Memory]
    # Partition_HM_Table: state -> error identifier -> action.
    hm: dict[int, dict[int, str]] = field(default_factory=dict)
    # ima:Linux OutputFile ({node} filled in per node) and HealthMonitorLogPort.
    output_file: str | None = None
    hm_log_port: str | None = None

    def port(self, name: str) -> Port | None:
        return next((p for p in self.ports if p.name == name), None)

    @property
    def rate_hz(self) -> float:
        return NS_PER_S / self.period_ns


@dataclass
class Window:
    ident: int
    partition: str
    start_ns: int
    duration_ns: int

    @property
    def end_ns(self) -> int:
        return self.start_ns + self.duration_ns


@dataclass
class Endpoint:
    partition: str
    port: str

    def __str__(self) -> str:
        return f"{self.partition}.{self.port}"


@dataclass
class Channel:
    ident: int
    name: str
    source: Endpoint
    destinations: list[Endpoint]


@dataclass
class CanTraffic:
    """The CAN messages one partition instance sends and receives on one node."""

    sends: list[str]
    receives: list[str]


@dataclass
class System:
    """A loaded, checked system model. Times are exact integers of nanoseconds (`*_ns`)."""

    name: str
    path: Path
    source: str  # the system file as generated files name it (relative to the repository)
    application: str
    version: str | None
    time_mode: str | None
    nodes: list[Node]
    partitions: list[Partition]
    replicated: list[str]
    major_frame_ns: int
    windows: list[Window]
    hm_system: dict[int, dict[int, str]]  # System_HM_Table: state -> error -> level
    hm_module: dict[int, dict[int, str]]  # Module_HM_Table: state -> error -> action
    channels: list[Channel]
    can: dict  # {"dbc": Path, "bitrate": int}
    # {"config": Path, "security": off|auth|sign|encrypt, "liveliness_lease_s", "deadline_s",
    #  "topics": [names]}
    dds: dict
    dds_topics: list[dict]  # [{"name", "partition"}]
    voting: dict  # {"thresholds": {axis: float}, "persist": int, "offset_s": float}
    membership: dict  # {"heartbeat": str, "missed_frames": int}
    # node name -> partition name -> its CAN traffic on that node ({channel} expanded).
    can_traffic: dict[str, dict[str, CanTraffic]] = field(default_factory=dict)
    messages_header: str | None = None  # the C header declaring the ports' message types
    included: list[Path] = field(default_factory=list)  # the file(s) the model includes

    @property
    def major_frame_s(self) -> float:
        return self.major_frame_ns / NS_PER_S

    def partition(self, name: str) -> Partition | None:
        return next((p for p in self.partitions if p.name == name), None)

    def node(self, name: str) -> Node | None:
        return next((n for n in self.nodes if n.name == name), None)

    def argument_values(self, node: Node) -> dict[str, str]:
        """What each ARGUMENT_FIELDS name stands for on `node`."""
        v = self.voting
        return {
            "node": node.name,
            "node_index": str(node.index),
            "node_channel": node.channel,
            "node_indices": ",".join(str(i) for i in sorted(n.index for n in self.nodes)),
            "canbus_socket": canbus_socket_name(),
            "dds_socket": dds_socket_name(node.index),
            "vote_thresholds": ",".join(f"{float(v['thresholds'][a]):g}" for a in VOTING_AXES),
            "vote_persist": str(v["persist"]),
            "membership_missed_frames": str(self.membership["missed_frames"]),
        }

    def arguments(self, partition: Partition, node: Node) -> list[str]:
        """The partition's arguments on `node`, every {name} filled in."""
        values = self.argument_values(node)
        return [_FIELD.sub(lambda m: values[m.group(1)], w) for w in partition.arguments]

    def channel_of(self, partition: str, port: str) -> Channel | None:
        """The channel a port is an end of, if any."""
        for ch in self.channels:
            ends = [ch.source, *ch.destinations]
            if any(e.partition == partition and e.port == port for e in ends):
                return ch
        return None
