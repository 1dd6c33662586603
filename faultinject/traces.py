# SPDX-License-Identifier: Apache-2.0
"""What a run left in its run directory, as the oracles read it: each node's SKE trace, the
bus trace (every frame, decoded where the oracles need it), the world's events and truth, the
DDS agents' traces, and the modules the nodes ran. Read once, lazily, and kept as raw lines:
a minute of triplex flight leaves some 70,000 records, most of which are the same as the
golden run's. Those are compared as bytes (a partition's windows, its port hashes, the frames
of a few identifiers) and only what an oracle asks for, or what differs, is parsed."""

from __future__ import annotations

import bisect
import functools
import json
import re
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
    try:
        with open(path, "rb") as f:
            return parse_lines(f)
    except OSError:
        return []


def parse_lines(lines) -> list[dict]:
    """The records of raw JSON lines; a line cut by a killed writer is skipped."""
    out = []
    for line in lines:
        try:
            rec = orjson.loads(line)
        except orjson.JSONDecodeError:
            continue  # a line cut by a killed writer
        if isinstance(rec, dict):
            out.append(rec)
    return out


_KIND = b'"kind":"'
_PARTITION = b'"partition":"'
# The SKE's records that come by the thousand, kept by partition as well as by kind: the
# oracles compare them with the golden run's partition by partition.
_BY_PARTITION = {b"window_start": "window", b"window_end": "window", b"port_hash": "port_hash"}


def t_ns_of(line: bytes) -> int:
    """The time of a raw record; every writer of the run starts its records with t_ns (a
    line cut before it ends, or another one, is read whole)."""
    if line.startswith(b'{"t_ns":'):
        end = line.find(b",", 8)
        if end > 8:
            try:
                return int(line[8:end])
            except ValueError:
                pass
    try:
        return int(orjson.loads(line).get("t_ns", 1 << 62))
    except (orjson.JSONDecodeError, AttributeError, TypeError, ValueError):
        return 1 << 62  # a line cut by a killed writer: after everything


def before(lines: list[bytes], limit: int) -> list[bytes]:
    """The raw records written before `limit` (a trace is written in time order)."""
    return lines[:bisect.bisect_left(lines, limit, key=t_ns_of)]


def read_compact(path: Path) -> bytes:
    """A JSON-lines file's bytes, every record in the compact form the run's writers use
    (`"kind":"hm"`, no blanks); a file another tool rewrote with blanks is made compact here,
    line by line, so that its records are found all the same."""
    try:
        data = path.read_bytes()
    except OSError:
        return b""
    first = data[:data.find(b"\n")] if b"\n" in data else data
    if not first or _KIND in first or b'"kind"' not in first:
        return data
    out = []
    for line in data.splitlines():
        try:
            out.append(orjson.dumps(orjson.loads(line)))
        except orjson.JSONDecodeError:
            out.append(line)
    return b"\n".join(out) + b"\n"


class RawTrace:
    """One JSON-lines trace as raw lines, by kind (and the SKE's window and port-hash records
    by partition too), each parsed only when asked: most of a run's records are compared with
    the golden run's as bytes and never parsed."""

    def __init__(self, path: Path) -> None:
        kinds: dict[bytes, list[bytes]] = defaultdict(list)
        grouped: dict[tuple[str, bytes], list[bytes]] = defaultdict(list)
        data = read_compact(path)
        for line in data.splitlines():
            i = line.find(_KIND)
            if i < 0:
                continue  # not a record of a kind (or cut before it): nobody asks for it
            j = line.find(b'"', i + 8)
            kind = line[i + 8:j]
            group = _BY_PARTITION.get(kind)
            if group is not None:
                a = line.find(_PARTITION)
                if a > 0:
                    grouped[(group, line[a + 13:line.find(b'"', a + 13)])].append(line)
                    continue
            kinds[kind].append(line)
        self._kinds = kinds
        # the partition names as JSON wrote them, decoded once
        self._groups: dict[tuple[str, str], list[bytes]] = {}
        for (group, raw), lines in grouped.items():
            try:
                name = orjson.loads(b'"' + raw + b'"')
            except orjson.JSONDecodeError:
                continue  # a name cut by a killed writer
            self._groups.setdefault((group, name), []).extend(lines)
        self._parsed: dict = {}

    def kind(self, kind: str) -> list[dict]:
        """The records of one kind, parsed (the window and port-hash records: group())."""
        if kind not in self._parsed:
            self._parsed[kind] = parse_lines(self._kinds.get(kind.encode(), ()))
        return self._parsed[kind]

    def group(self, group: str, partition: str) -> list[bytes]:
        """A partition's raw `window` (window_start and window_end, in the order written) or
        `port_hash` records."""
        return self._groups.get((group, partition), [])

    def partitions(self, group: str) -> list[str]:
        return sorted(name for g, name in self._groups if g == group)


def lines_matching(data: bytes, rx: re.Pattern) -> list[bytes]:
    """The lines of `data` in which `rx` matches, in order, found by the regular expression
    at C speed rather than line by line."""
    out = []
    end = -1
    for m in rx.finditer(data):
        at = m.start()
        if at < end:
            continue  # a second match in the same line
        start = data.rfind(b"\n", 0, at) + 1
        end = data.find(b"\n", at)
        if end < 0:
            end = len(data)
        out.append(data[start:end])
    return out


_CAN_TX = b'"kind":"can_tx"'
_NOT_CAN_TX = re.compile(rb'"kind":"(?!can_tx")')


class BusTrace:
    """The bus's trace: every frame on the wire (can_tx, tens of thousands a minute) and a
    few other records. The oracles want a few identifiers, a sender, or the other records:
    those lines are found in the raw bytes, and only they are parsed."""

    def __init__(self, path: Path) -> None:
        self.data = read_compact(path)
        self._others: dict[str, list[bytes]] = defaultdict(list)
        for line in lines_matching(self.data, _NOT_CAN_TX):
            i = line.find(_KIND)
            self._others[line[i + 8:line.find(b'"', i + 8)].decode(errors="replace")].append(line)
        self._parsed: dict[str, list[dict]] = {}

    def kind(self, kind: str) -> list[dict]:
        if kind not in self._parsed:
            lines = self.tx_lines if kind == "can_tx" else self._others.get(kind, [])
            self._parsed[kind] = parse_lines(lines)
        return self._parsed[kind]

    @functools.cached_property
    def tx_lines(self) -> list[bytes]:
        return lines_matching(self.data, re.compile(re.escape(_CAN_TX)))

    def tx_matching(self, rx: re.Pattern) -> list[bytes]:
        """The can_tx lines in which rx matches."""
        return [x for x in lines_matching(self.data, rx) if _CAN_TX in x]

    def last_tx_t_ns(self) -> int | None:
        end = len(self.data)
        while True:
            at = self.data.rfind(_CAN_TX, 0, end)
            if at < 0:
                return None
            start = self.data.rfind(b"\n", 0, at) + 1
            stop = self.data.find(b"\n", at)
            line = self.data[start:stop if stop >= 0 else len(self.data)]
            if line.rstrip().endswith(b"}"):  # not a line cut by a killed writer
                return t_ns_of(line)
            end = start


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


def _field(raw: int, start: int, mask: int, scale: float, offset: float):
    value = (raw >> start) & mask
    return value * scale + offset if scale != 1 or offset else value


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
    def _node(self, node: str) -> RawTrace:
        cache = self.__dict__.setdefault("_nodes", {})
        if node not in cache:
            cache[node] = RawTrace(self.run_dir / f"{node}.jsonl")
        return cache[node]

    def node_kind(self, node: str, kind: str) -> list[dict]:
        """The node's SKE records of one kind (not `window_*` nor `port_hash`: windows(),
        port_hashes())."""
        return self._node(node).kind(kind) if node in self.nodes else []

    def window_lines(self, node: str, partition: str) -> list[bytes]:
        """The partition's window_start and window_end records, raw, as the SKE wrote them."""
        return self._node(node).group("window", partition) if node in self.nodes else []

    def windows(self, node: str, partition: str) -> list[tuple]:
        """(kind, t_ns, frame, window, yielded, yield_t_ns) of the partition's windows."""
        return [(e["kind"], e["t_ns"], e.get("frame"), e.get("window"), e.get("yielded"),
                 e.get("yield_t_ns")) for e in parse_lines(self.window_lines(node, partition))]

    def window_lateness(self, node: str, partition: str) -> list[int]:
        """How long after its wall-clock time each of the partition's windows started (ns;
        `ima launch --realtime` only: the SKE's `wall_late_ns`)."""
        return [e["wall_late_ns"] for e in parse_lines(self.window_lines(node, partition))
                if e.get("kind") == "window_start" and "wall_late_ns" in e]

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

    def port_hash_partitions(self, node: str) -> list[str]:
        """The partitions whose source ports the node's SKE hashed."""
        return self._node(node).partitions("port_hash") if node in self.nodes else []

    def port_hash_lines(self, node: str, partition: str) -> list[bytes]:
        """The partition's port_hash records, raw, in the order the SKE wrote them."""
        return self._node(node).group("port_hash", partition) if node in self.nodes else []

    def port_hashes(self, node: str, partition: str) -> dict[str, list[tuple[int, str]]]:
        """port -> [(t_ns, hash)] of the partition's source ports, window by window."""
        out: dict[str, list[tuple[int, str]]] = defaultdict(list)
        for e in parse_lines(self.port_hash_lines(node, partition)):
            out[e["port"]].append((e["t_ns"], e["hash"]))
        return out

    def app_messages(self, node: str) -> list[dict]:
        return self.node_kind(node, "app_message")

    # -- the bus ----------------------------------------------------------------------------
    @functools.cached_property
    def _bus(self) -> BusTrace:
        return BusTrace(self.run_dir / "can.jsonl")

    @functools.cached_property
    def frames(self) -> list[dict]:
        """Every frame on the wire (can_tx), parsed: the CAN classes' evidence only."""
        return self._bus.kind("can_tx")

    def frame_lines(self, *can_ids: int) -> list[bytes]:
        """The raw can_tx records of these identifiers, in time order."""
        cache = self.__dict__.setdefault("_frame_lines", {})
        if can_ids not in cache:
            cache[can_ids] = self._bus.tx_matching(re.compile(
                rb'"id":(?:%b),' % b"|".join(b"%d" % i for i in can_ids))) if can_ids else []
        return cache[can_ids]

    def frames_of(self, *can_ids: int) -> list[dict]:
        """The frames of these identifiers, picked from the raw records before any is parsed."""
        cache = self.__dict__.setdefault("_frames_of", {})
        if can_ids not in cache:
            cache[can_ids] = [e for e in (self.frames if "frames" in self.__dict__ else
                                          parse_lines(self.frame_lines(*can_ids)))
                              if e.get("id") in can_ids]
        return cache[can_ids]

    def last_frame_t_ns(self) -> int | None:
        """The time of the last whole frame on the wire."""
        return self._bus.last_tx_t_ns()

    def frames_from(self, sender: str) -> list[dict]:
        """The frames a client of the bus sent (`node2/io`, `world`)."""
        cache = self.__dict__.setdefault("_frames_from", {})
        if sender not in cache:
            tag = re.compile(re.escape(b'"from":' + orjson.dumps(sender) + b","))
            cache[sender] = [e for e in parse_lines(self._bus.tx_matching(tag))
                             if e.get("from") == sender]
        return cache[sender]

    def bus_kind(self, *kinds: str) -> list[dict]:
        """The bus's records of these kinds, in time order."""
        if len(kinds) == 1:
            return self._bus.kind(kinds[0])
        return sorted((e for k in kinds for e in self._bus.kind(k)), key=lambda e: e["t_ns"])

    def decode(self, frame: dict) -> dict[str, Any]:
        msg = _dbc().get_message_by_frame_id(frame["id"])
        return msg.decode(bytes.fromhex(frame["data"]), decode_choices=False)

    @functools.cached_property
    def _fcs_raw(self) -> list[tuple[int, int, int]]:
        """(t_ns, channel 0..2, payload as a little-endian integer) of every FCS heartbeat."""
        return [(e["t_ns"], e["id"] - _FCS_STATUS_BASE,
                 int.from_bytes(bytes.fromhex(e["data"]), "little"))
                for e in self.frames_of(*(_FCS_STATUS_BASE + k for k in range(3)))]

    @functools.cached_property
    def fcs_status(self) -> list[tuple[int, int, dict]]:
        """(t_ns, node index 1..3, decoded FCS_STATUS_x) of every heartbeat on the bus."""
        layouts = _fcs_layouts()
        return [(t, rci + 1, {name: _field(raw, start, mask, scale, offset)
                              for name, start, mask, scale, offset in layouts[rci]})
                for t, rci, raw in self._fcs_raw]

    def fcs_field(self, field: str) -> dict[int, tuple[list[int], list]]:
        """node index -> (times, values) of one FCS_STATUS field, heartbeat by heartbeat
        (that field alone decoded)."""
        cache = self.__dict__.setdefault("_fcs_fields", {})
        if field not in cache:
            where = [{name: rest for name, *rest in fields}.get(field)
                     for fields in _fcs_layouts()]
            out: dict[int, tuple[list[int], list]] = {}
            for t, rci, raw in self._fcs_raw:
                times, values = out.setdefault(rci + 1, ([], []))
                times.append(t)
                values.append(None if where[rci] is None else _field(raw, *where[rci]))
            cache[field] = out
        return cache[field]

    def fcs_at(self, field: str, t_ns: int):
        """The field's value in the last heartbeat at or before t_ns (of any channel), None
        before the first."""
        best = None
        for times, values in self.fcs_field(field).values():
            i = bisect.bisect_right(times, t_ns) - 1
            if i >= 0 and (best is None or times[i] > best[0]):
                best = (times[i], values[i])
        return None if best is None else best[1]

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
        """Each agent's trace up to the end of the run: what it saw of the run. At the end the
        nodes stop, then the agents (each traces the others' going as `dds_peer_left`), and on
        a loaded host the agents may idle past their liveliness lease between the two
        (`dds_peer_lost`, liveliness). Every trace is cut where the run ended for the first
        agent (the wall-clock time of the first `io_disconnect` or `dds_stop` of the run's
        last frame), each at its own `dds_stop` at the latest."""
        traces = {n: read_jsonl(self.run_dir / f"dds{k}.jsonl")
                  for k, n in enumerate(self.nodes, start=1)}
        last = max((e.get("t_ns", 0) for events in traces.values() for e in events), default=0)
        ends = [e["t_wall_ns"] for events in traces.values() for e in events
                if e.get("kind") in ("dds_stop", "io_disconnect")
                and isinstance(e.get("t_wall_ns"), int)
                and e.get("t_ns", 0) >= last - 50_000_000]
        first_stop = min(ends, default=None)
        out = {}
        for n, events in traces.items():
            stop = next((i for i, e in enumerate(events) if e.get("kind") == "dds_stop" or (
                first_stop is not None and e.get("t_wall_ns", 0) >= first_stop)), len(events))
            out[n] = events[:stop]
        return out

    # -- every injector's `fault` events ----------------------------------------------------
    @functools.cached_property
    def fault_events(self) -> list[dict]:
        """Every `fault` event of the run, whoever wrote it (io's come as app messages
        `fault FID CLASS STATE DETAIL`)."""
        out = []
        for node in self.nodes:
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
