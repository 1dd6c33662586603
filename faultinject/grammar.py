# SPDX-License-Identifier: Apache-2.0
"""The two written forms of a fault: the short command-line form and the YAML form (validated
by faultinject/faults.schema.json), both checked against the catalogue.

Short form (docs/fault-injection.md):

    WHERE ":" CLASS "@" WHEN [ "~" DURATION ] [ ":" KEY "=" VALUE ("," KEY "=" VALUE)* ]

    WHERE    NODE | PARTITION "@" NODE | PARTITION "." PORT_OR_PROCESS "@" NODE | world | bus
             NODE is a node's name, or * for every node at once (a common-mode fault)
    WHEN     SECONDS | mode=MODE [+SECONDS] | after=FAULT_ID [+SECONDS]
    DURATION SECONDS                   transient: active that long
           | ON "/" PERIOD ["/" LENGTH] intermittent: ON seconds in every PERIOD (within LENGTH)
             none: permanent

e.g. nav_fcs@node2:memory_violation@60, node2:node_crash@120, world:gps_loss@100~30,
io@node1:wrong_output@60:mode=random, nav_fcs@*:numeric_error@60 (common mode),
nav_fcs.ACT_CMD_OUT@node3:stuck_output@mode=AUTOPILOT+5.
"""

from __future__ import annotations

import functools
import json
import math
import re
from pathlib import Path
from typing import Any

import yaml

from faultinject import catalogue
from faultinject.model import Duration, Fault, Target, Trigger
from ima.errors import ImaError

SCHEMA = Path(__file__).resolve().parent / "faults.schema.json"
_NAME = r"[A-Za-z][A-Za-z0-9_\-]*"
_FID = re.compile(r"^[A-Za-z0-9_\-]{1,15}$")
_WHERE = re.compile(rf"^(?:(?P<part>{_NAME})(?:\.(?P<member>{_NAME}))?@)?(?P<node>{_NAME}|\*)$")
MODES = ("INIT", "DIRECT", "AUTOPILOT", "MISSION", "CONTINGENCY")


class FaultSpecError(ImaError):
    def __init__(self, message: str) -> None:
        super().__init__(message, exit_code=2)


def _seconds(text: str, what: str, spec: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise FaultSpecError(f"fault '{spec}': {what} '{text}' is not a number of "
                             "seconds") from None
    if not math.isfinite(v) or v < 0:
        raise FaultSpecError(f"fault '{spec}': {what} must be a finite number >= 0, not '{text}'")
    return v


def _when(text: str, spec: str) -> Trigger:
    head, plus, delay = text.partition("+")
    delay_s = _seconds(delay, "the delay", spec) if plus else 0.0
    if head.startswith("mode="):
        mode = head[5:]
        if mode not in MODES:
            raise FaultSpecError(f"fault '{spec}': mode must be one of {', '.join(MODES)}")
        return Trigger(mode=mode, delay_s=delay_s)
    if head.startswith("after="):
        fid = head[6:]
        if not _FID.match(fid):
            raise FaultSpecError(f"fault '{spec}': after= names a fault id, not '{fid}'")
        return Trigger(after=fid, delay_s=delay_s)
    if plus:
        raise FaultSpecError(f"fault '{spec}': +SECONDS follows a condition (mode=, after=)")
    return Trigger(at_s=_seconds(head, "the time", spec))


def _duration(text: str, spec: str) -> Duration:
    if not text:
        return Duration()
    parts = text.split("/")
    if len(parts) == 1:
        length = _seconds(parts[0], "the duration", spec)
        if length <= 0:
            raise FaultSpecError(f"fault '{spec}': a transient fault lasts more than 0 s")
        return Duration("transient", length_s=length)
    if len(parts) > 3:
        raise FaultSpecError(f"fault '{spec}': ~ON/PERIOD[/LENGTH]")
    on, period = (_seconds(p, "the intermittent spell", spec) for p in parts[:2])
    if not 0 < on <= period:
        raise FaultSpecError(f"fault '{spec}': an intermittent fault needs 0 < ON <= PERIOD")
    length = _seconds(parts[2], "the length", spec) if len(parts) == 3 else None
    return Duration("intermittent", length_s=length, on_s=on, period_s=period)


def _param(fc: catalogue.FaultClass, key: str, value: Any, spec: str) -> Any:
    p = fc.params.get(key)
    if p is None:
        known = ", ".join(fc.params) or "none"
        raise FaultSpecError(f"fault '{spec}': {fc.name} has no parameter '{key}' (its "
                             f"parameters: {known})")
    text = str(value)
    if p.type == "choice":
        if text not in p.choices:
            raise FaultSpecError(f"fault '{spec}': {key} must be one of {', '.join(p.choices)}")
        return text
    if p.type in ("number", "int"):
        try:
            v = float(text) if p.type == "number" else int(text, 0)
        except ValueError:
            raise FaultSpecError(f"fault '{spec}': {key}={text} is not a number") from None
        if isinstance(v, float) and not math.isfinite(v):
            raise FaultSpecError(f"fault '{spec}': {key}={text} is not finite")
        return v
    if p.type == "time" and not re.match(r"^\d+(\.\d+)?(ns|us|ms|s)?$", text):
        raise FaultSpecError(f"fault '{spec}': {key}={text} is not a time (e.g. 20ms, 2s)")
    if p.type == "name" and not re.match(r"^[A-Za-z0-9_.\-/]+$", text):
        raise FaultSpecError(f"fault '{spec}': {key}={text} has characters a name may not")
    return text


def _target(fc: catalogue.FaultClass, where: str, spec: str) -> Target:
    if where in ("world", "bus"):
        if fc.target not in (where,) and not (where == "bus" and fc.target == "client"):
            raise FaultSpecError(f"fault '{spec}': {fc.name} targets a {fc.target}, not {where}")
        return Target(node=where)
    m = _WHERE.match(where)
    if not m:
        raise FaultSpecError(f"fault '{spec}': '{where}' is not NODE, PARTITION@NODE, "
                             "PARTITION.PORT@NODE, world or bus")
    part, member, node = m.group("part"), m.group("member"), m.group("node")
    need = fc.target
    if need in ("world", "bus"):
        raise FaultSpecError(f"fault '{spec}': {fc.name} acts on the {need}: write {need}:")
    if need in ("node", "client"):
        if part:
            raise FaultSpecError(f"fault '{spec}': {fc.name} targets a node: write NODE:")
        return Target(node=node)
    if not part:
        shape = {"partition": "PARTITION@NODE", "port": "PARTITION.PORT@NODE",
                 "process": "PARTITION.PROCESS@NODE"}[need]
        raise FaultSpecError(f"fault '{spec}': {fc.name} targets a {need}: write {shape}")
    if need == "partition" and member:
        raise FaultSpecError(f"fault '{spec}': {fc.name} targets a partition, not one of its "
                             "ports or processes")
    if need == "port" and not member:
        raise FaultSpecError(f"fault '{spec}': {fc.name} targets a port: PARTITION.PORT@NODE")
    return Target(node=node, partition=part, process=member if need == "process" else None,
                  port=member if need == "port" else None)


def parse(spec: str, fid: str) -> Fault:
    """One fault from its short form; FaultSpecError (exit 2) saying what is wrong."""
    where, sep, rest = spec.partition(":")
    if not sep or not rest:
        raise FaultSpecError(f"fault '{spec}': expected WHERE:CLASS@WHEN (e.g. "
                             "nav_fcs@node2:memory_violation@60)")
    head, _, params_text = rest.partition(":")
    cls, at_sep, when_dur = head.partition("@")
    if not at_sep:
        raise FaultSpecError(f"fault '{spec}': expected CLASS@WHEN after '{where}:'")
    try:
        fc = catalogue.get(cls)
    except ImaError as exc:
        raise FaultSpecError(f"fault '{spec}': {exc}") from None
    when, _, dur = when_dur.partition("~")
    params: dict[str, Any] = {}
    for kv in filter(None, params_text.split(",")):
        key, eq, value = kv.partition("=")
        if not eq or not key:
            raise FaultSpecError(f"fault '{spec}': '{kv}' is not KEY=VALUE")
        if key in params:
            raise FaultSpecError(f"fault '{spec}': parameter '{key}' given twice")
        params[key] = _param(fc, key, value, spec)
    for name, p in fc.params.items():
        if p.required and name not in params:
            raise FaultSpecError(f"fault '{spec}': {fc.name} needs {name}=")
    return Fault(fid=fid, cls=fc.name, target=_target(fc, where, spec), trigger=_when(when, spec),
                 duration=_duration(dur, spec), params=params)


@functools.cache
def _schema() -> dict:
    return json.loads(SCHEMA.read_text(encoding="utf-8"))


def from_yaml_file(path: Path, first: int = 1) -> list[Fault]:
    """The faults of a YAML file (`faults:` list, faults.schema.json); ImaError naming the bad
    path. Each item is either {spec: SHORT_FORM, id} or the long form; ids f<first>, ...
    where not given."""
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise FaultSpecError(f"{path}: cannot read: {exc}") from exc
    except yaml.YAMLError as exc:
        raise FaultSpecError(f"{path}: not valid YAML: {exc}") from exc
    import jsonschema  # here: most launches have no faults file, and it takes 0.05 s

    e = first_schema_error(jsonschema.Draft202012Validator(_schema()), doc)
    if e is not None:
        raise FaultSpecError(f"{path}: {e}")
    return from_items(doc["faults"], str(path), first)


def first_schema_error(validator, doc) -> str | None:
    """The first error of a document, as `PATH: MESSAGE`; of an item that matches none of its
    alternatives (oneOf), the most relevant error of the alternatives, which names the bad
    value."""
    from jsonschema.exceptions import best_match

    found = [best_match([e]) for e in validator.iter_errors(doc)]
    if not found:
        return None
    e = sorted(found, key=lambda e: list(map(str, e.absolute_path)))[0]
    return f"{'.'.join(str(p) for p in e.absolute_path) or '(top level)'}: {e.message}"


def from_items(items: list[dict], origin: str, first: int = 1) -> list[Fault]:
    """Faults from their YAML items (also a campaign's); ids f<N> from `first` where not given."""
    out: list[Fault] = []
    for i, item in enumerate(items):
        fid = item.get("id") or f"f{first + i}"
        spec = item.get("spec") or long_to_short(item)
        try:
            out.append(parse(spec, fid))
        except FaultSpecError as exc:
            raise FaultSpecError(f"{origin}: faults[{i}]: {exc}") from None
    return check_ids(out, origin)


def long_to_short(item: dict) -> str:
    """The long YAML form as a short form (one parser checks both)."""
    t = item["target"]
    where = t if isinstance(t, str) else t.get("node", "")
    if isinstance(t, dict) and t.get("partition"):
        member = t.get("port") or t.get("process")
        where = f"{t['partition']}{'.' + member if member else ''}@{t['node']}"
    trig = item.get("trigger", {})
    if "at_s" in item:
        when = f"{item['at_s']}"
    elif "mode" in trig:
        when = f"mode={trig['mode']}" + (f"+{trig['delay_s']}" if trig.get("delay_s") else "")
    else:
        when = f"after={trig['after']}" + (f"+{trig['delay_s']}" if trig.get("delay_s") else "")
    d = item.get("duration") or {}
    dur = ""
    if d.get("kind") == "transient":
        dur = f"~{d['length_s']}"
    elif d.get("kind") == "intermittent":
        dur = f"~{d['on_s']}/{d['period_s']}" + (f"/{d['length_s']}" if "length_s" in d else "")
    params = ",".join(f"{k}={v}" for k, v in (item.get("params") or {}).items())
    return f"{where}:{item['class']}@{when}{dur}" + (f":{params}" if params else "")


def check_ids(faults: list[Fault], origin: str) -> list[Fault]:
    """Unique ids, and every after= names an earlier fault of the run."""
    seen: set[str] = set()
    for f in faults:
        if f.fid in seen:
            raise FaultSpecError(f"{origin}: fault id '{f.fid}' used twice")
        if f.trigger.after is not None and f.trigger.after not in seen:
            raise FaultSpecError(f"{origin}: fault {f.fid}: after={f.trigger.after} names no "
                                 "earlier fault of the run")
        seen.add(f.fid)
    return faults
