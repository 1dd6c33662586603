# SPDX-License-Identifier: Apache-2.0
"""Reads a system model (YAML), validates it against config/schema/system.schema.json, then
checks the rules a schema cannot express; every error names the file, line and value path."""

from __future__ import annotations

import functools
import json
import math
import os
from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ima import paths, schema_memo
from ima.deploy.locate import path_text
from ima.deploy.model import (
    ARGUMENT_FIELDS,
    HM_ERRORS,
    HM_STATES,
    NS_PER_S,
    VOTING_AXES,
    CanTraffic,
    Channel,
    Endpoint,
    Memory,
    Node,
    Partition,
    Port,
    Process,
    System,
    SystemModelError,
    Window,
    argument_fields,
    seconds_text,
)
from ima.deploy.source import Source, read_source

if TYPE_CHECKING:
    import jsonschema

MAX_ERRORS_SHOWN = 5
QUEUE_BYTES_MAX = 64 * 1024 * 1024  # the SKE's limit on one queuing port
MAX_DESTINATIONS = 16

# Errors that can never be handled at PROCESS level, and states in which no process could go
# on: the SKE's loader refuses both (docs/health-monitoring.md).
_NO_PROCESS_LEVEL_ERRORS = {"WINDOW_OVERRUN", "PARTITION_EXIT"}
_NO_PROCESS_LEVEL_STATES = {"MODULE_INIT", "PARTITION_INIT", "ERROR_HANDLER"}


def schema_path() -> Path:
    return paths.repo_root() / "config" / "schema" / "system.schema.json"


@functools.cache
def _schema_text() -> bytes:
    path = schema_path()
    try:
        return path.read_bytes()
    except OSError as exc:
        raise SystemModelError(f"{path}: cannot read the system model schema: {exc}") from exc


@functools.cache
def _schema() -> dict:
    try:
        return json.loads(_schema_text())
    except ValueError as exc:
        raise SystemModelError(f"{schema_path()}: cannot read the system model schema: "
                               f"{exc}") from exc


def display_name(path: Path) -> str:
    """The system file as generated files name it: relative to the repository if inside it."""
    resolved = path.resolve()
    root = paths.repo_root().resolve()
    try:
        return resolved.relative_to(root).as_posix()
    except ValueError:
        return resolved.as_posix()


class _Reporter:
    """Builds the one-line errors: `FILE:LINE: PATH: MESSAGE` (the file that holds the value)."""

    def __init__(self, source: Source) -> None:
        self.source = source

    def where(self, parts: tuple) -> str:
        return self.source.where(parts)

    def line(self, parts: tuple) -> int:
        return self.source.file_of(parts).locator.line(parts) or 0

    def fail(self, parts: tuple, message: str) -> SystemModelError:
        return SystemModelError(f"{self.where(parts)}: {path_text(parts)}: {message}")


def load_system(path: Path | str) -> System:
    """Loads and checks a system model (and the file it includes); raises ImaError
    (SystemModelError) naming what is wrong."""
    path = Path(path)
    source = read_source(path)
    rep = _Reporter(source)
    _validate_schema(source.doc, rep)
    _check_finite(source.doc, (), rep)
    return _Builder(source.doc, path, rep).build()


def _validate_schema(doc: Any, rep: _Reporter) -> None:
    """The schema's errors, the first few of them named (a model found valid before is not
    validated again: ima.schema_memo)."""
    if schema_memo.known_valid(_schema_text(), doc):
        return
    import jsonschema

    validator = jsonschema.Draft202012Validator(_schema())
    # An error of an alternative ("not valid under any of the given schemas") is replaced by
    # the most relevant error of its alternatives, which names the value at fault.
    found = [jsonschema.exceptions.best_match([e]) for e in validator.iter_errors(doc)]
    errors = sorted(found,
                    key=lambda e: (rep.line(tuple(e.absolute_path)),
                                   list(map(str, e.absolute_path)), e.message))
    if not errors:
        schema_memo.remember_valid(_schema_text(), doc)
        return
    first = errors[0]
    parts = tuple(first.absolute_path)
    text = f"{rep.where(parts)}: {path_text(parts)}: {_message(first)}"
    for e in errors[1:MAX_ERRORS_SHOWN]:
        p = tuple(e.absolute_path)
        text += f"; {rep.where(p)}: {path_text(p)}: {_message(e)}"
    if len(errors) > MAX_ERRORS_SHOWN:
        text += f" (and {len(errors) - MAX_ERRORS_SHOWN} more)"
    raise SystemModelError(text)


def _check_finite(value: Any, parts: tuple, rep: _Reporter) -> None:
    """YAML's .nan passes every numeric bound of a schema: refuse it (and .inf) here."""
    if isinstance(value, float) and not math.isfinite(value):
        raise rep.fail(parts, f"{value} is not a finite number")
    if isinstance(value, dict):
        for k, v in value.items():
            _check_finite(v, parts + (k,), rep)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _check_finite(v, parts + (i,), rep)


def _message(error: jsonschema.ValidationError) -> str:
    """The validator's message; a pattern says in words what it expects."""
    described = isinstance(error.schema, dict) and error.schema.get("description")
    if error.validator == "pattern" and described:
        return f"{error.message} (expected {described})"
    return error.message


def _ns(value: int | float) -> Decimal:
    """Seconds as written (0.05 is 50000000, not the nearest binary fraction) in nanoseconds."""
    exact = Decimal(repr(value)) if isinstance(value, float) else Decimal(value)
    return exact * NS_PER_S


def _fmt(ns: int) -> str:
    return f"{seconds_text(ns)} s"


class _Builder:
    """Turns a schema-valid document into a System, checking the cross-references."""

    def __init__(self, doc: dict, path: Path, rep: _Reporter) -> None:
        self.doc = doc
        self.path = path
        self.rep = rep
        self.source = rep.source

    def fail(self, parts: tuple, message: str) -> SystemModelError:
        return self.rep.fail(parts, message)

    def seconds(self, parts: tuple, value: int | float) -> int:
        ns = _ns(value)
        if ns != ns.to_integral_value():
            raise self.fail(parts, f"{value} is not a whole number of nanoseconds "
                                   "(at most 9 decimals)")
        return int(ns)

    def file(self, top_key: str, value: str) -> Path:
        """A path written under `top_key`, relative to the folder of the file that wrote it."""
        p = Path(os.path.expanduser(value))
        return p if p.is_absolute() else (self.source.base(top_key) / p).resolve()

    # -- the parts, in the order of the file ---------------------------------------------

    def build(self) -> System:
        d = self.doc
        nodes = self.nodes()
        major_frame_ns = self.seconds(("schedule", "major_frame_s"), d["schedule"]["major_frame_s"])
        partitions = self.partitions(major_frame_ns)
        replicated = self.replicated(partitions)
        windows = self.windows(partitions, major_frame_ns)
        hm_system = self.hm_system()
        hm_module = self.hm_table(d["health_monitoring"].get("module") or {})
        channels = self.intra_node(partitions)
        can, traffic = self.can(nodes, partitions)
        dds, topics = self.dds(partitions)
        voting = self.voting(major_frame_ns)
        membership = self.membership(nodes, can)
        header = self.messages_header(partitions)
        return System(
            name=d["system"], path=self.path.resolve(), source=display_name(self.path),
            application=d["application"],
            version=None if d.get("version") is None else str(d["version"]),
            time_mode=d.get("time_mode"),
            nodes=nodes, partitions=partitions, replicated=replicated,
            major_frame_ns=major_frame_ns, windows=windows, hm_system=hm_system,
            hm_module=hm_module, channels=channels, can=can, dds=dds, dds_topics=topics,
            voting=voting, membership=membership, can_traffic=traffic,
            messages_header=header, included=self.source.included(),
        )

    def messages_header(self, partitions: list[Partition]) -> str | None:
        header = self.doc.get("messages_header")
        if header is None:
            for i, p in enumerate(partitions):
                for k, po in enumerate(p.ports):
                    if po.message:
                        raise self.fail(("partitions", i, "ports", k, "message"),
                                        f"{p.name}.{po.name} names its message type "
                                        f"{po.message}, but no messages_header declares it")
        return header

    def nodes(self) -> list[Node]:
        out: list[Node] = []
        for i, n in enumerate(self.doc["nodes"]):
            for j, other in enumerate(out):
                if other.name == n["name"]:
                    raise self.fail(("nodes", i, "name"),
                                    f"'{n['name']}' is already the name of nodes[{j}]")
                if other.index == n["index"]:
                    raise self.fail(("nodes", i, "index"),
                                    f"{n['index']} is already the index (redundancy channel) "
                                    f"of nodes[{j}] ({other.name})")
            out.append(Node(n["name"], n["index"]))
        return out

    def partitions(self, major_frame_ns: int) -> list[Partition]:
        out: list[Partition] = []
        for i, p in enumerate(self.doc["partitions"]):
            at = ("partitions", i)
            for j, other in enumerate(out):
                if other.name == p["name"]:
                    raise self.fail(at + ("name",),
                                    f"'{p['name']}' is already the name of partitions[{j}]")
                if other.name.upper() == p["name"].upper():
                    raise self.fail(at + ("name",),
                                    f"'{p['name']}' and partitions[{j}] '{other.name}' differ "
                                    "only in case: their C glue would have the same names")
            if p["name"].upper() == self.doc["application"].upper():
                raise self.fail(at + ("name",),
                                f"'{p['name']}' is the application's name: its C glue would "
                                "clash with the system header's")
            period_ns = self.seconds(at + ("period_s",), p["period_s"])
            if major_frame_ns % period_ns:
                raise self.fail(at + ("period_s",),
                                f"{p['period_s']} does not divide the major frame "
                                f"({_fmt(major_frame_ns)}): the major frame must be a whole "
                                "number of partition periods")
            out.append(Partition(
                ident=i + 1, name=p["name"], criticality=p["criticality"],
                system_partition=bool(p.get("system_partition", False)),
                personality=p["personality"], executable=p["executable"],
                arguments=self.arguments(at, p.get("arguments") or []), period_ns=period_ns,
                processes=self.processes(at, p["processes"], period_ns),
                ports=self.ports(at, p["ports"]),
                memory=[Memory(m["size"], m.get("type"), m.get("access"))
                        for m in p.get("memory") or []],
                hm=self.hm_table(p.get("health_monitoring") or {}),
                output_file=p.get("output_file"),
                hm_log_port=self.hm_log_port(at, p),
            ))
        return out

    def hm_log_port(self, at: tuple, p: dict) -> str | None:
        """The port that receives the module's HM decisions: a destination queuing port of
        the partition, large enough for one (ske_hm_log_t), on no channel."""
        name = p.get("hm_log_port")
        if name is None:
            return None
        port = next((q for q in p["ports"] if q["name"] == name), None)
        if port is None or port["kind"] != "queuing" or port["direction"] != "destination" \
                or port["size"] < HM_LOG_SIZE:
            raise self.fail(at + ("hm_log_port",),
                            f"'{name}' must be one of {p['name']}'s destination queuing ports, "
                            f"of at least {HM_LOG_SIZE} bytes (one health-monitor decision)")
        return name

    def arguments(self, at: tuple, words: list[str]) -> list[str]:
        """Arguments whose {names} are all ARGUMENT_FIELDS (filled in per node on deploy)."""
        for k, word in enumerate(words):
            rest = word
            for name in argument_fields(word):
                if name not in ARGUMENT_FIELDS:
                    raise self.fail(at + ("arguments", k),
                                    f"'{{{name}}}' in '{word}' is not a field deploy fills in "
                                    f"(fields: {', '.join(ARGUMENT_FIELDS)})")
                rest = rest.replace(f"{{{name}}}", "")
            if "{" in rest or "}" in rest:
                raise self.fail(at + ("arguments", k),
                                f"'{word}': a brace that does not enclose a field name")
        return list(words)

    def c_name(self, at: tuple, name: str, taken: list[str], what: str) -> None:
        """A port or process name is unique in its partition, also once upper-cased (the C
        glue's macros), and is not COUNT (the glue's <PARTITION>_PORT_COUNT)."""
        for other in taken:
            if other == name:
                raise self.fail(at, f"'{name}' is already the name of a {what} of this "
                                    "partition")
            if other.upper() == name.upper():
                raise self.fail(at, f"'{name}' and the {what} '{other}' differ only in case: "
                                    "their C glue would have the same names")
        if name.upper() == "COUNT":
            plural = "processes" if what == "process" else f"{what}s"
            raise self.fail(at, f"'{name}' is reserved: the C glue counts the {plural} as "
                                f"<PARTITION>_{what.upper()}_COUNT")

    def processes(self, at: tuple, items: list[dict], period_ns: int) -> list[Process]:
        out: list[Process] = []
        for k, pr in enumerate(items):
            here = at + ("processes", k)
            self.c_name(here + ("name",), pr["name"], [o.name for o in out], "process")
            per = self.seconds(here + ("period_s",), pr["period_s"])
            if per % period_ns:
                raise self.fail(here + ("period_s",),
                                f"{pr['period_s']} is not a multiple of the partition period "
                                f"({_fmt(period_ns)}): periodic processes are released at "
                                "partition period starts")
            off = self.seconds(here + ("offset_s",), pr.get("offset_s", 0))
            if off >= per:
                raise self.fail(here + ("offset_s",),
                                f"{pr.get('offset_s')} is not within the process period "
                                f"({_fmt(per)})")
            out.append(Process(pr["name"], per, pr["stack"], pr["priority"], off,
                               pr.get("deadline", "soft")))
        return out

    def ports(self, at: tuple, items: list[dict]) -> list[Port]:
        out: list[Port] = []
        for k, po in enumerate(items):
            here = at + ("ports", k)
            self.c_name(here + ("name",), po["name"], [o.name for o in out], "port")
            if po["kind"] == "sampling":
                if "max_messages" in po:
                    raise self.fail(here + ("max_messages",),
                                    "only a queuing port has a queue capacity")
                refresh = self.seconds(here + ("refresh_s",), po["refresh_s"])
                out.append(Port(po["name"], po["direction"], "sampling", po["size"],
                                refresh_ns=refresh, message=po.get("message")))
            else:
                if "refresh_s" in po:
                    raise self.fail(here + ("refresh_s",),
                                    "only a sampling port has a refresh period")
                if po["size"] * po["max_messages"] > QUEUE_BYTES_MAX:
                    raise self.fail(here + ("max_messages",),
                                    f"{po['max_messages']} messages of {po['size']} bytes "
                                    "exceed the 64 MiB a queuing port may hold")
                out.append(Port(po["name"], po["direction"], "queuing", po["size"],
                                max_messages=po["max_messages"], message=po.get("message")))
        return out

    def replicated(self, partitions: list[Partition]) -> list[str]:
        names = [p.name for p in partitions]
        seen: list[str] = []
        for i, r in enumerate(self.doc["replicated"]):
            if r not in names:
                raise self.fail(("replicated", i),
                                f"no partition named '{r}' (partitions: {', '.join(names)})")
            if r in seen:
                raise self.fail(("replicated", i), f"'{r}' is listed twice")
            seen.append(r)
        return seen

    def windows(self, partitions: list[Partition], maf: int) -> list[Window]:
        by_name = {p.name: p for p in partitions}
        items = self.doc["schedule"]["windows"]
        placed: list[tuple[int, Window]] = []  # (index in the file, window)
        for i, w in enumerate(items):
            at = ("schedule", "windows", i)
            if w["partition"] not in by_name:
                raise self.fail(at + ("partition",),
                                f"no partition named '{w['partition']}' "
                                f"(partitions: {', '.join(by_name)})")
            start = self.seconds(at + ("start_s",), w["start_s"])
            dur = self.seconds(at + ("duration_s",), w["duration_s"])
            win = Window(0, w["partition"], start, dur)
            if win.end_ns > maf:
                raise self.fail(at, f"window of '{win.partition}' runs from {_fmt(start)} to "
                                    f"{_fmt(win.end_ns)}, past the major frame of {_fmt(maf)}")
            for j, other in placed:
                if start < other.end_ns and other.start_ns < win.end_ns:
                    raise self.fail(at, f"window of '{win.partition}' [{_fmt(start)}, "
                                        f"{_fmt(win.end_ns)}) overlaps schedule.windows[{j}] of "
                                        f"'{other.partition}' [{_fmt(other.start_ns)}, "
                                        f"{_fmt(other.end_ns)})")
            placed.append((i, win))
        # Per partition: every period of the major frame gets the same window time, and no
        # window crosses the end of its period (the SKE's load-time rules).
        for pi, p in enumerate(partitions):
            mine = [(i, w) for i, w in placed if w.partition == p.name]
            if not mine:
                raise self.fail(("partitions", pi),
                                f"partition '{p.name}' has no window in schedule.windows")
            per_period = [0] * (maf // p.period_ns)
            for i, w in mine:
                k = w.start_ns // p.period_ns
                if w.end_ns > (k + 1) * p.period_ns:
                    raise self.fail(("schedule", "windows", i),
                                    f"window of '{p.name}' [{_fmt(w.start_ns)}, "
                                    f"{_fmt(w.end_ns)}) crosses the end of its partition "
                                    f"period at {_fmt((k + 1) * p.period_ns)}")
                per_period[k] += w.duration_ns
            if len(set(per_period)) > 1:
                got = ", ".join(_fmt(t) for t in per_period)
                raise self.fail(("partitions", pi, "period_s"),
                                f"the periods of '{p.name}' get different window time ({got}): "
                                "every partition period must get the same")
        ordered = sorted((w for _, w in placed), key=lambda w: w.start_ns)
        for ident, w in enumerate(ordered, 1):
            w.ident = ident
        return ordered

    def hm_system(self) -> dict[int, dict[int, str]]:
        at = ("health_monitoring", "system")
        table = self.doc["health_monitoring"].get("system") or {}
        for state, errors in table.items():
            for err, level in errors.items():
                if level == "PROCESS" and (state in _NO_PROCESS_LEVEL_STATES
                                           or err in _NO_PROCESS_LEVEL_ERRORS):
                    why = (f"{err} is detected by the SKE" if err in _NO_PROCESS_LEVEL_ERRORS
                           else f"in state {state} no ARINC process runs")
                    raise self.fail(at + (state, err),
                                    f"PROCESS level needs a process whose error handler could "
                                    f"act: {why}")
        return self.hm_table(table)

    @staticmethod
    def hm_table(table: dict) -> dict[int, dict[int, str]]:
        """A table keyed by names as identifiers: state -> error -> level or action."""
        out: dict[int, dict[int, str]] = {}
        for state, errors in table.items():
            if errors:
                out[HM_STATES[state][0]] = {HM_ERRORS[e][0]: v for e, v in errors.items()}
        return {s: dict(sorted(e.items())) for s, e in sorted(out.items())}

    def endpoint(self, at: tuple, ref: str, by_name: dict[str, Partition]) -> tuple[Endpoint, Port]:
        part, port = ref.split(".", 1)
        if part not in by_name:
            raise self.fail(at, f"no partition named '{part}' (partitions: {', '.join(by_name)})")
        p = by_name[part].port(port)
        if p is None:
            ports = ", ".join(x.name for x in by_name[part].ports) or "none"
            raise self.fail(at, f"partition '{part}' has no port named '{port}' "
                                f"(its ports: {ports})")
        return Endpoint(part, port), p

    def intra_node(self, partitions: list[Partition]) -> list[Channel]:
        by_name = {p.name: p for p in partitions}
        used: dict[tuple[str, str], int] = {}  # (partition, port) -> index of its channel
        out: list[Channel] = []
        for i, c in enumerate(self.doc["channels"]["intra_node"]):
            at = ("channels", "intra_node", i)
            if any(o.name == c["name"] for o in out):
                raise self.fail(at + ("name",), f"'{c['name']}' is already the name of a channel")

            def claim(where: tuple, e: Endpoint, i: int = i, name: str = c["name"]) -> None:
                key = (e.partition, e.port)
                if key in used:
                    j = used[key]
                    other = out[j].name if j < len(out) else name
                    raise self.fail(where, f"{e} is already an end of channels.intra_node[{j}] "
                                           f"({other}): a port belongs to one channel")
                used[key] = i

            src, sport = self.endpoint(at + ("from",), c["from"], by_name)
            claim(at + ("from",), src)
            if not sport.is_source:
                raise self.fail(at + ("from",),
                                f"{src} is a destination port: a channel's source must be a "
                                "source port")
            dests: list[Endpoint] = []
            targets = c["to"] if isinstance(c["to"], list) else [c["to"]]
            for k, ref in enumerate(targets):
                where = at + (("to", k) if isinstance(c["to"], list) else ("to",))
                dst, dport = self.endpoint(where, ref, by_name)
                claim(where, dst)
                if dport.is_source:
                    raise self.fail(where, f"{dst} is a source port: a channel's destination "
                                           "must be a destination port")
                if dport.kind != sport.kind:
                    raise self.fail(where, f"{dst} is a {dport.kind} port but the source {src} "
                                           f"is a {sport.kind} port")
                if dport.size != sport.size:
                    raise self.fail(where, f"{dst} has size {dport.size} but the source {src} "
                                           f"has {sport.size}: the ends of a channel have the "
                                           "same size")
                dests.append(dst)
            if sport.kind == "queuing" and len(dests) != 1:
                raise self.fail(at + ("to",), f"a queuing channel has exactly one destination, "
                                              f"not {len(dests)}")
            out.append(Channel(i + 1, c["name"], src, dests))
        return out

    def can(self, nodes: list[Node], partitions: list[Partition]
            ) -> tuple[dict, dict[str, dict[str, CanTraffic]]]:
        at = ("channels", "can")
        spec = self.doc["channels"]["can"]
        dbc = self.file("channels", spec["dbc"])
        messages = self.dbc_messages(at + ("dbc",), dbc)
        self.can_messages = messages
        names = [p.name for p in partitions]
        traffic: dict[str, dict[str, CanTraffic]] = {n.name: {} for n in nodes}
        for part, lists in spec["partitions"].items():
            here = at + ("partitions", part)
            if part not in names:
                raise self.fail(here, f"no partition named '{part}' (partitions: "
                                      f"{', '.join(names)})")
            for node in nodes:
                sends = self.expand(here + ("sends",), lists.get("sends") or [], node, nodes,
                                    messages, dbc, sending=True)
                receives = self.expand(here + ("receives",), lists.get("receives") or [], node,
                                       nodes, messages, dbc, sending=False)
                traffic[node.name][part] = CanTraffic(sends, receives)
        return {"dbc": dbc, "bitrate": spec["bitrate"]}, traffic

    def dbc_messages(self, at: tuple, dbc: Path) -> dict[str, int]:
        """The DBC's messages: name -> frame identifier."""
        if not dbc.is_file():
            raise self.fail(at, f"no such file: {dbc}")
        try:
            return dict(_dbc_ids(str(dbc.resolve()), dbc.stat().st_mtime_ns))
        except Exception as exc:  # cantools raises many kinds for a bad file
            raise self.fail(at, f"cannot read {dbc}: {exc}") from exc

    def expand(self, at: tuple, items: list[str], node: Node, nodes: list[Node],
               messages: dict[str, int], dbc: Path, sending: bool) -> list[str]:
        out: list[str] = []
        for k, name in enumerate(items):
            where = at + (k,)
            if "{channels}" in name:
                if sending:
                    raise self.fail(where, f"'{name}': a node sends on its own redundancy "
                                           "channel only: use {channel}")
                expanded = [name.replace("{channels}", n.channel) for n in nodes]
            else:
                expanded = [name.replace("{channel}", node.channel)]
            for msg in expanded:
                if msg not in messages:
                    raise self.fail(where, f"'{msg}' ({node.name}) is not a message of "
                                           f"{dbc.name}")
                if sending and "{channel}" in name and messages[msg] & 0x3 != node.rci:
                    raise self.fail(where, f"'{msg}' has redundancy channel "
                                           f"{messages[msg] & 0x3} in its identifier "
                                           f"0x{messages[msg]:08X}, not {node.rci} "
                                           f"({node.name}, channel {node.channel})")
                if msg in out:
                    raise self.fail(where, f"'{msg}' is listed twice")
                out.append(msg)
        return out

    def dds(self, partitions: list[Partition]) -> tuple[dict, list[dict]]:
        at = ("channels", "dds")
        spec = self.doc["channels"]["dds"]
        names = [p.name for p in partitions]
        topics: list[dict] = []
        for i, t in enumerate(spec["topics"]):
            if any(o["name"] == t["name"] for o in topics):
                raise self.fail(at + ("topics", i, "name"), f"'{t['name']}' is listed twice")
            if t["partition"] not in names:
                raise self.fail(at + ("topics", i, "partition"),
                                f"no partition named '{t['partition']}' (partitions: "
                                f"{', '.join(names)})")
            topics.append({"name": t["name"], "partition": t["partition"]})
        config = self.file("channels", spec["config"])
        if not config.is_file():
            raise self.fail(at + ("config",), f"no such file: {config}")
        lease = self.seconds(at + ("liveliness_lease_s",), spec["liveliness_lease_s"])
        deadline = self.seconds(at + ("deadline_s",), spec["deadline_s"])
        return {
            "config": config,
            "security": spec.get("security", "sign"),
            "liveliness_lease_s": lease / NS_PER_S,
            "deadline_s": deadline / NS_PER_S,
            "topics": [t["name"] for t in topics],
        }, topics

    def voting(self, maf: int) -> dict:
        v = self.doc["voting"]
        off = self.seconds(("voting", "offset_s"), v["offset_s"])
        if off >= maf:
            raise self.fail(("voting", "offset_s"),
                            f"{v['offset_s']} is not within the major frame ({_fmt(maf)})")
        return {
            "thresholds": {a: float(v["thresholds"][a]) for a in VOTING_AXES},
            "persist": v["persist"],
            "offset_s": off / NS_PER_S,
        }

    def membership(self, nodes: list[Node], can: dict) -> dict:
        m = self.doc["membership"]
        for node in nodes:
            msg = f"{m['heartbeat']}_{node.channel}"
            if msg not in self.can_messages:
                raise self.fail(("membership", "heartbeat"),
                                f"no message {msg} ({node.name}'s heartbeat on channel "
                                f"{node.channel}) in {can['dbc'].name}")
        return {"heartbeat": m["heartbeat"], "missed_frames": m["missed_frames"]}


# sizeof(ske_hm_log_t) (ske/abi/include/ske_abi.h): one decision of the module's HM log.
HM_LOG_SIZE = 232


@functools.lru_cache(maxsize=8)
def _dbc_ids(path: str, mtime_ns: int) -> tuple[tuple[str, int], ...]:
    """A DBC's (message name, frame identifier), read once per version of the file (a
    campaign loads the same model for every run), from the build tree's cache of it when it
    is there (ima.canbus.dbc_table)."""
    from ima.canbus import dbc_table

    return tuple((m["name"], m["frame_id"]) for m in dbc_table.table(Path(path)))
