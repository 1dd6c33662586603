# SPDX-License-Identifier: Apache-2.0
"""A run's faults against its system: targets checked and expanded (a common-mode fault is one
injection per node), triggers resolved to emulated times, and the command-line words each
injector gets (the CAN bus, each node's SKE, io and DDS agent, the world)."""

from __future__ import annotations

from dataclasses import dataclass, field

from faultinject import catalogue
from faultinject.grammar import FaultSpecError
from faultinject.model import NS_PER_S, Fault, Target

# The bus's name for each CAN class (its --fault kinds).
BUS_KINDS = {"can_drop": "can_drop", "can_corrupt": "can_corrupt", "can_delay": "can_delay",
             "can_duplicate": "can_duplicate", "babbling_idiot": "babbling_idiot",
             "can_bus_off": "can_bus_off", "transceiver_cut": "transceiver_cut",
             "rx_drop": "rx_drop"}


@dataclass(frozen=True)
class Injection:
    """One fault as one injector applies it (a common-mode fault is one per node)."""

    fault: Fault
    node: str | None  # the node it acts on; None for the world and the bus itself

    @property
    def fid(self) -> str:
        return self.fault.fid


@dataclass
class Plan:
    """The resolved faults and each injector's words."""

    faults: list[Fault]
    injections: list[Injection]
    kills: dict[str, float] = field(default_factory=dict)  # node -> emulated s
    hangs: dict[str, float] = field(default_factory=dict)
    bus: list[str] = field(default_factory=list)
    world: list[str] = field(default_factory=list)
    ske: dict[str, list[str]] = field(default_factory=dict)  # node -> words
    io: dict[str, list[str]] = field(default_factory=dict)  # node -> io's extra arguments
    dds: dict[str, list[str]] = field(default_factory=dict)  # node -> agent words

    def by_fid(self, fid: str) -> Fault:
        return next(f for f in self.faults if f.fid == fid)


def _ns(seconds: float) -> int:
    return round(seconds * NS_PER_S)


def timing(f: Fault) -> str:
    """fid=,at=,until=,period=,on= in the injectors' grammar (faultinject/include/fi/spec.h)."""
    words = [f"fid={f.fid}", f"at={f.at_ns}"]
    d = f.duration
    if d.length_s is not None:
        words.append(f"until={f.at_ns + _ns(d.length_s)}")
    if d.kind == "intermittent":
        words += [f"period={_ns(d.period_s)}", f"on={_ns(d.on_s)}"]
    return ",".join(words)


def _params(f: Fault, skip: tuple[str, ...] = ()) -> list[str]:
    """The class's parameters, its defaults filled in (the injectors have none of their own
    for what the catalogue defines)."""
    fc = catalogue.get(f.cls)
    given = {k: p.default for k, p in fc.params.items() if p.default is not None} | f.params
    return [f"{k}={v}" for k, v in given.items() if k not in skip]


def check_target(system, f: Fault) -> None:
    """The target exists in the system and suits the class (a port fault on a source port)."""
    fc = catalogue.get(f.cls)
    t = f.target
    names = [n.name for n in system.nodes]
    if t.node not in ("world", "bus", "*") and t.node not in names:
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): no node '{t.node}' in {system.name} "
                             f"(nodes: {', '.join(names)})")
    if t.node == "bus" and f.cls == "transceiver_cut":
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): transceiver_cut cuts one node's "
                             "transceiver: write NODE:, not bus:")
    if fc.injector == "dds" and len(names) < 2:
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): {system.name} has one node and no "
                             "DDS between nodes")
    if t.partition is None:
        return
    p = system.partition(t.partition)
    if p is None:
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): no partition '{t.partition}' "
                             f"(partitions: {', '.join(x.name for x in system.partitions)})")
    if f.cls == "disk_full" and not p.output_file:
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): {p.name} has no output file (no "
                             "output_file in the system model): disk_full fills the disk under "
                             "one")
    if t.process is not None and t.process not in [x.name for x in p.processes]:
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): {p.name} has no process "
                             f"'{t.process}'")
    if t.port is not None:
        port = p.port(t.port)
        if port is None:
            raise FaultSpecError(f"fault {f.fid} ({f.spec()}): {p.name} has no port '{t.port}'")
        if not port.is_source:
            raise FaultSpecError(f"fault {f.fid} ({f.spec()}): {p.name}.{t.port} is a "
                                 f"destination port: {f.cls} acts on a source port")
        if f.cls == "queuing_flood" and port.kind != "queuing":
            raise FaultSpecError(f"fault {f.fid} ({f.spec()}): {p.name}.{t.port} is not a "
                                 "queuing port")


def resolve_after(faults: list[Fault]) -> list[Fault]:
    """after=FID+D triggers, resolved from the faults they follow (in order)."""
    out: list[Fault] = []
    for f in faults:
        if f.trigger.after is not None:
            base = next(x for x in out if x.fid == f.trigger.after)
            if base.trigger.at_s is None:
                out.append(f)  # its base waits for a condition: resolved with it
                continue
            f = f.at(base.trigger.at_s + f.trigger.delay_s)
        out.append(f)
    return out


def compile_plan(system, faults: list[Fault], duration_s: float) -> Plan:
    """Every fault must be resolved (an emulated time) and start within the run."""
    for f in faults:
        if f.trigger.at_s is None:
            raise FaultSpecError(f"fault {f.fid} ({f.spec()}): its trigger is not resolved")
        if f.trigger.at_s >= duration_s:
            raise FaultSpecError(f"fault {f.fid} ({f.spec()}): starts at {f.trigger.at_s:g} s, "
                                 f"after the end of the run ({duration_s:g} s)")
        check_target(system, f)
    plan = Plan(faults=list(faults), injections=[])
    index = {n.name: n.index for n in system.nodes}
    for f in faults:
        nodes = [n.name for n in system.nodes] if f.target.node == "*" else [f.target.node]
        for node in nodes:
            _inject(plan, system, f, node if node not in ("world", "bus") else None, index)
    return plan


def _inject(plan: Plan, system, f: Fault, node: str | None, index: dict[str, int]) -> None:
    fc = catalogue.get(f.cls)
    plan.injections.append(Injection(f, node))
    t = Target(node=node or f.target.node, partition=f.target.partition,
               process=f.target.process, port=f.target.port)
    if fc.injector == "world":
        plan.world += ["--fault", ":".join([f.cls, ",".join([timing(f), *_params(f)])])]
    elif fc.injector == "ske":
        words = [timing(f)]
        if t.partition:
            words.append(f"partition={t.partition}")
        if t.process:
            words.append(f"process={t.process}")
        if t.port:
            words.append(f"port={t.port}")
        words += _params(f)
        plan.ske.setdefault(node, []).extend(["--fault", f"{f.cls}:{','.join(words)}"])
    elif fc.injector == "io":
        plan.io.setdefault(node, []).append(
            f"--fault={f.cls}:{','.join([timing(f), *_params(f)])}")
    elif fc.injector == "dds":
        plan.dds.setdefault(node, []).extend(
            ["--fault", f"{f.cls}:{','.join([timing(f), *_params(f)])}"])
    elif f.cls == "node_crash":
        _once(plan.kills, f, node)
    elif f.cls == "node_freeze":
        _once(plan.hangs, f, node)
    else:  # the bus's CAN classes: a node's io is its client on the bus
        words = [timing(f)]
        if node is not None:
            words.append(f"client={node}/io")
        words += _params(f)
        plan.bus += ["--fault", f"{BUS_KINDS[f.cls]}:{','.join(words)}"]


def _once(chosen: dict[str, float], f: Fault, node: str) -> None:
    if f.duration.kind != "permanent":
        raise FaultSpecError(f"fault {f.fid} ({f.spec()}): a node stopped stays stopped: "
                             f"{f.cls} is permanent")
    chosen[node] = min(f.trigger.at_s, chosen.get(node, f.trigger.at_s))
