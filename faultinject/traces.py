# SPDX-License-Identifier: Apache-2.0
"""What a run left in its run directory, as the oracles read it: each node's SKE trace, the
bus trace (every frame, decoded where the oracles need it), the world's events and truth, the
DDS agents' traces, and the modules the nodes ran. Read once, lazily."""

from __future__ import annotations

import functools
import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import cantools
import orjson

from ima import paths

_FCS_STATUS_BASE = 0x8B00960  # FCS_STATUS_A; B, C differ in the two redundancy bits


def read_jsonl(path: Path) -> list[dict]:
    """Every record of a JSON-lines file (orjson: a run's traces are 10^5 lines and more); a
    line cut short by a killed writer is skipped, a missing file is empty."""
    out = []
    try:
        with open(path, "rb") as f:
            for line in f:
                try:
                    rec = orjson.loads(line)
                except orjson.JSONDecodeError:
                    continue  # a line cut by a killed writer
                if isinstance(rec, dict):
                    out.append(rec)
    except OSError:
        pass
    return out


@functools.cache
def _dbc():
    return cantools.database.load_file(str(paths.repo_root() / "config" / "can" / "rpas.dbc"))


@functools.cache
def _fcs_layouts() -> list[list[tuple[str, int, int, float, float]]]:
    """Per channel A, B, C: (signal name without its channel suffix, start bit, mask, scale,
    offset) of FCS_STATUS_x's signals, every one little-endian and unsigned (checked): decoded
    with shifts, the same values as cantools' decode, many times faster."""
    out = []
    for ch in "ABC":
        fields = []
        for sig in _dbc().get_message_by_name(f"FCS_STATUS_{ch}").signals:
            if sig.byte_order != "little_endian" or sig.is_signed or sig.is_float:
                raise ValueError(f"{sig.name}: not a little-endian unsigned signal")
            fields.append((sig.name.rsplit("_", 1)[0], sig.start, (1 << sig.length) - 1,
                           sig.scale, sig.offset))
        out.append(fields)
    return out


def fcs_choices(signal: str) -> dict[int, str]:
    """The DBC's value table of an FCS_STATUS signal ("FCS_MODE", "FCS_FALLBACK")."""
    sig = _dbc().get_message_by_name("FCS_STATUS_A").get_signal_by_name(f"{signal}_A")
    return {int(k): str(v) for k, v in (sig.choices or {}).items()}


class RunTraces:
    """One run directory's records."""

    def __init__(self, run_dir: Path) -> None:
        self.run_dir = Path(run_dir)
        try:
            self.launch = json.loads((self.run_dir / "launch.json").read_text())
        except (OSError, ValueError):
            self.launch = {}
        self.nodes: list[str] = list(self.launch.get("nodes") or [])

    # -- the SKEs ---------------------------------------------------------------------------
    @functools.cached_property
    def node_events(self) -> dict[str, list[dict]]:
        return {n: read_jsonl(self.run_dir / f"{n}.jsonl") for n in self.nodes}

    @functools.cached_property
    def _node_by_kind(self) -> dict[str, dict[str, list[dict]]]:
        out: dict[str, dict[str, list[dict]]] = {}
        for node, events in self.node_events.items():
            kinds: dict[str, list[dict]] = defaultdict(list)
            for e in events:
                kinds[e.get("kind")].append(e)
            out[node] = kinds
        return out

    def node_kind(self, node: str, kind: str) -> list[dict]:
        return self._node_by_kind.get(node, {}).get(kind, [])

    def windows(self, node: str, partition: str) -> list[tuple]:
        """(kind, t_ns, frame, window, yielded, yield_t_ns) of the partition's windows."""
        cache = self.__dict__.setdefault("_windows", {})
        if node not in cache:
            per: dict[str, list[tuple]] = defaultdict(list)
            for e in self.node_events.get(node, []):
                if e.get("kind") in ("window_start", "window_end"):
                    per[e.get("partition")].append(
                        (e["kind"], e["t_ns"], e.get("frame"), e.get("window"), e.get("yielded"),
                         e.get("yield_t_ns")))
            cache[node] = per
        return cache[node].get(partition, [])

    def window_lateness(self, node: str, partition: str) -> list[int]:
        """How long after its wall-clock time each of the partition's windows started (ns;
        `ima launch --realtime` only: the SKE's `wall_late_ns`)."""
        return [e["wall_late_ns"] for e in self.node_events.get(node, [])
                if e.get("kind") == "window_start" and e.get("partition") == partition
                and "wall_late_ns" in e]

    def stats(self, node: str) -> dict:
        """The node's SKE statistics (nodeK.json), {} when it wrote none."""
        try:
            return json.loads((self.run_dir / f"{node}.json").read_text())
        except (OSError, ValueError):
            return {}

    def cpu_ns(self, node: str, partition: str) -> int | None:
        """The CPU time the partition used, as the SKE measured it on the host."""
        return next((p.get("cpu_ns") for p in self.stats(node).get("partitions", [])
                     if p.get("name") == partition), None)

    @property
    def realtime(self) -> bool:
        return bool(self.launch.get("realtime"))

    @property
    def host_cpus(self) -> int | None:
        """The CPUs the run could use (None: a run recorded before launch.json said)."""
        n = self.launch.get("host_cpus")
        return n if isinstance(n, int) and n > 0 else None

    def port_hashes(self, node: str) -> dict[tuple[str, str], list[tuple[int, str]]]:
        """(partition, port) -> [(t_ns, hash)] of the node's source ports, window by window."""
        cache = self.__dict__.setdefault("_port_hashes", {})
        if node not in cache:
            out: dict[tuple[str, str], list[tuple[int, str]]] = defaultdict(list)
            for e in self.node_kind(node, "port_hash"):
                out[(e["partition"], e["port"])].append((e["t_ns"], e["hash"]))
            cache[node] = out
        return cache[node]

    def app_messages(self, node: str) -> list[dict]:
        return self.node_kind(node, "app_message")

    # -- the bus ----------------------------------------------------------------------------
    @functools.cached_property
    def can(self) -> list[dict]:
        return read_jsonl(self.run_dir / "can.jsonl")

    @functools.cached_property
    def frames(self) -> list[dict]:
        return self._can_by_kind.get("can_tx", [])

    def frames_of(self, can_id: int) -> list[dict]:
        return [e for e in self.frames if e.get("id") == can_id]

    @functools.cached_property
    def _can_by_kind(self) -> dict[str, list[dict]]:
        by: dict[str, list[dict]] = defaultdict(list)
        for e in self.can:
            by[e.get("kind")].append(e)
        return by

    def bus_kind(self, *kinds: str) -> list[dict]:
        """The bus's records of these kinds, in time order."""
        if len(kinds) == 1:
            return self._can_by_kind.get(kinds[0], [])
        return sorted((e for k in kinds for e in self._can_by_kind.get(k, [])),
                      key=lambda e: e["t_ns"])

    def decode(self, frame: dict) -> dict[str, Any]:
        msg = _dbc().get_message_by_frame_id(frame["id"])
        return msg.decode(bytes.fromhex(frame["data"]), decode_choices=False)

    @functools.cached_property
    def fcs_status(self) -> list[tuple[int, int, dict]]:
        """(t_ns, node index 1..3, decoded FCS_STATUS_x) of every heartbeat on the bus."""
        out = []
        layouts = _fcs_layouts()
        for e in self.frames:
            rci = e["id"] - _FCS_STATUS_BASE
            if 0 <= rci <= 2:
                raw = int.from_bytes(bytes.fromhex(e["data"]), "little")
                d = {name: ((raw >> start) & mask) * scale + offset if scale != 1 or offset
                     else (raw >> start) & mask for name, start, mask, scale, offset
                     in layouts[rci]}
                out.append((e["t_ns"], rci + 1, d))
        return out

    # -- the world --------------------------------------------------------------------------
    @functools.cached_property
    def world(self) -> list[dict]:
        return read_jsonl(self.run_dir / "world.jsonl")

    def world_kind(self, kind: str) -> list[dict]:
        by = self.__dict__.get("_world_by_kind")
        if by is None:
            by = defaultdict(list)
            for e in self.world:
                by[e.get("kind")].append(e)
            self.__dict__["_world_by_kind"] = by
        return by.get(kind, [])

    @functools.cached_property
    def truth(self) -> list[dict]:
        return read_jsonl(self.run_dir / "truth.jsonl")

    @functools.cached_property
    def truth_bytes(self) -> bytes:
        try:
            return (self.run_dir / "truth.jsonl").read_bytes()
        except OSError:
            return b""

    # -- the DDS agents ---------------------------------------------------------------------
    @functools.cached_property
    def dds(self) -> dict[str, list[dict]]:
        """Each agent's trace up to its `dds_stop`: what it saw of the run. At the end of the
        run the agents are stopped one by one, and each sees the others go (`dds_peer_lost`)."""
        out = {}
        for k, n in enumerate(self.nodes, start=1):
            events = read_jsonl(self.run_dir / f"dds{k}.jsonl")
            stop = next((i for i, e in enumerate(events) if e.get("kind") == "dds_stop"),
                        len(events))
            out[n] = events[:stop]
        return out

    # -- every injector's `fault` events ----------------------------------------------------
    @functools.cached_property
    def fault_events(self) -> list[dict]:
        """Every `fault` event of the run, whoever wrote it (io's come as app messages
        `fault FID CLASS STATE DETAIL`)."""
        out = []
        for node in self.node_events:
            events = sorted(self.node_kind(node, "fault") + self.node_kind(node, "app_message"),
                            key=lambda e: e["t_ns"])
            for e in events:
                if e.get("kind") == "fault":
                    out.append(dict(e, node=node))
                elif e.get("kind") == "app_message" and e.get("text", "").startswith("fault "):
                    parts = e["text"].split(" ", 4)
                    if len(parts) >= 4:
                        out.append({"t_ns": e["t_ns"], "node": node, "src": e.get("src"),
                                    "kind": "fault", "fid": parts[1], "class": parts[2],
                                    "state": parts[3], "detail": parts[4] if len(parts) > 4
                                    else ""})
        out += self.bus_kind("fault")
        out += [e for e in self.world if e.get("kind") == "fault"]
        for node, events in self.dds.items():
            out += [dict(e, node=node) for e in events if e.get("kind") == "fault"]
        return sorted(out, key=lambda e: (e.get("t_ns", 0), str(e.get("fid"))))

    def module(self, node: str) -> Path:
        return Path(self.launch.get("modules", {}).get(node, self.run_dir / "deploy" /
                                                            f"{node}.xml"))
