# SPDX-License-Identifier: Apache-2.0
"""The fault catalogue (faultinject/catalogue.yaml), loaded and checked: every class, its
injector, target, parameters, and what a run of it must show."""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ima.errors import ImaError

CATALOGUE = Path(__file__).resolve().parent / "catalogue.yaml"

LAYERS = ("partition", "node", "can", "dds", "sensor", "environment", "actuator")
INJECTORS = ("ske", "bus", "io", "dds", "world")
TARGETS = ("partition", "port", "process", "node", "client", "bus", "world")
DETECTORS = ("hm", "vote_out", "self_monitor", "membership", "dds_deadline", "nav_flags",
             "fallback", "bus_error", "mode", "none")
OUTCOMES = ("not_activated", "masked", "detected_recovered", "detected_degraded",
            "undetected_benign", "undetected_hazardous")
EVIDENCE = ("hm", "overrun", "port_silent", "port_changed", "frames_stopped", "frames_changed",
            "can_error", "frames_missing", "frames_late", "frames_duplicated", "frames_flood",
            "dds_missing", "sensor_frames", "pilot_frames", "truth_surface", "downlink_mode",
            "module_reset", "app_report", "command_departs")
ASKED_MODES = ("DIRECT", "AUTOPILOT", "MISSION")
# What a case may change: the expectations that depend on where and when the fault acts.
CASE_KEYS = ("evidence", "detect", "latency_ms", "mode", "masked", "outcomes", "known_limit")
# What a case's `when` may name: the mode the pilot asks for at the injection, the mode the
# flight control flies then, the target partition and port, and whether the fault is
# common-mode (every node at once).
WHEN_KEYS = ("asked", "flown", "partition", "port", "common_mode")
PARAM_TYPES = ("number", "int", "time", "name", "choice")


@dataclass(frozen=True)
class Param:
    name: str
    type: str
    default: Any = None
    choices: tuple = ()
    required: bool = False


@dataclass(frozen=True)
class FaultClass:
    name: str
    layer: str
    injector: str
    target: str
    evidence: tuple[str, ...]
    hm_error: str | None
    detect: dict[str, tuple[str, ...]]  # "redundant" / "single" -> detectors
    latency_ms: float
    outcomes: dict[str, tuple[str, ...]]
    masked: str  # bit_identical | tracking | none (for redundant systems)
    masked_reason: str | None = None
    mode: dict | None = None
    known_limit: dict | None = None
    params: dict[str, Param] = field(default_factory=dict)
    # (when, this class with the case's expectations): the first case that holds decides
    cases: tuple[tuple[dict, FaultClass], ...] = ()

    def case(self, **facts) -> FaultClass:
        """The class's expectations for a fault of it: those of the first of the catalogue's
        `cases` whose `when` holds of the facts (WHEN_KEYS: asked, flown, partition, port,
        common_mode), or the class's own."""
        for when, fc in self.cases:
            if all(facts.get(k) == v for k, v in when.items()):
                return fc
        return self

    def variant(self, redundant: bool) -> str:
        return "redundant" if redundant else "single"

    def detectors(self, redundant: bool) -> tuple[str, ...]:
        return self.detect[self.variant(redundant)]

    def expected_outcomes(self, redundant: bool) -> tuple[str, ...]:
        return self.outcomes[self.variant(redundant)]

    def known_limits(self) -> list[str]:
        """Every known limit the catalogue declares for the class, its own and its cases',
        each said with where it applies."""
        out = []
        if self.known_limit:
            out.append(f"{self.known_limit['applies']}: {self.known_limit['reason']}")
        for when, fc in self.cases:
            if fc.known_limit and fc.known_limit != self.known_limit:
                cond = ", ".join(k.replace("_", " ") if v is True else f"{k}={v}"
                                 for k, v in when.items())
                out.append(f"{cond}: {fc.known_limit['reason']}")
        return out

    def known_limit_applies(self, redundant: bool, common_mode: bool) -> bool:
        if not self.known_limit:
            return False
        applies = self.known_limit["applies"]
        return applies == "always" or (applies == "single" and not redundant) or \
            (applies == "common_mode" and common_mode)


def _fail(where: str, message: str) -> ImaError:
    return ImaError(f"{CATALOGUE.name}: {where}: {message}", exit_code=2)


def _choice(where: str, value: Any, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise _fail(where, f"{value!r} is not one of {', '.join(allowed)}")
    return value


def _pair(where: str, value: Any, allowed: tuple[str, ...]) -> dict[str, tuple[str, ...]]:
    if not isinstance(value, dict) or set(value) != {"redundant", "single"}:
        raise _fail(where, "expected {redundant: [...], single: [...]}")
    return {k: tuple(_choice(f"{where}.{k}", x, allowed) for x in v) for k, v in value.items()}


def _params(where: str, spec: dict) -> dict[str, Param]:
    out = {}
    for name, p in (spec or {}).items():
        ptype = _choice(f"{where}.{name}.type", p.get("type"), PARAM_TYPES)
        choices = tuple(p.get("choices") or ())
        if ptype == "choice" and not choices:
            raise _fail(f"{where}.{name}", "a choice needs its choices")
        out[name] = Param(name, ptype, p.get("default"), choices, bool(p.get("required")))
    return out


def _load_class(name: str, c: dict) -> FaultClass:
    where = f"classes.{name}"
    known = {"layer", "injector", "target", "params", "evidence", "hm_error", "detect",
             "latency_ms", "mode", "masked", "outcomes", "known_limit", "cases"}
    extra = set(c) - known
    if extra:
        raise _fail(where, f"unknown keys {sorted(extra)}")
    masked = c.get("masked") or {}
    limit = c.get("known_limit")
    if limit is not None and (limit.get("applies") not in ("always", "single", "common_mode")
                              or not limit.get("reason")):
        raise _fail(f"{where}.known_limit", "needs applies (always|single|common_mode) and reason")
    hm_error = c.get("hm_error")
    fc = FaultClass(
        name=name,
        layer=_choice(f"{where}.layer", c.get("layer"), LAYERS),
        injector=_choice(f"{where}.injector", c.get("injector"), INJECTORS),
        target=_choice(f"{where}.target", c.get("target"), TARGETS),
        evidence=tuple(_choice(f"{where}.evidence", e, EVIDENCE) for e in c.get("evidence", [])),
        hm_error=None if hm_error in (None, "none") else hm_error,
        detect=_pair(f"{where}.detect", c.get("detect"), DETECTORS),
        latency_ms=float(c.get("latency_ms", 0)),
        outcomes=_pair(f"{where}.outcomes", c.get("outcomes"), OUTCOMES),
        masked=_choice(f"{where}.masked.redundant", masked.get("redundant", "none"),
                       ("bit_identical", "tracking", "none")),
        masked_reason=masked.get("reason"),
        mode=c.get("mode"),
        known_limit=limit,
        params=_params(f"{where}.params", c.get("params")),
    )
    cases = []
    for i, case in enumerate(c.get("cases") or []):
        at = f"{where}.cases[{i}]"
        when = (case or {}).get("when")
        if not isinstance(when, dict) or not when or set(when) - set(WHEN_KEYS):
            raise _fail(at, f"needs `when` with any of {', '.join(WHEN_KEYS)}")
        for key in ("asked", "flown"):
            if key in when:
                _choice(f"{at}.when.{key}", when[key], ASKED_MODES)
        bad = set(case) - set(CASE_KEYS) - {"when"}
        if bad:
            raise _fail(at, f"a case may change only {', '.join(CASE_KEYS)}, not {sorted(bad)}")
        merged = {k: v for k, v in c.items() if k != "cases"}
        merged.update({k: v for k, v in case.items() if k != "when"})
        cases.append((dict(when), _load_class(name, merged)))
    return dataclasses.replace(fc, cases=tuple(cases)) if cases else fc


@functools.cache
def load() -> dict[str, FaultClass]:
    """Every class of the catalogue by name; ImaError if the catalogue is malformed."""
    try:
        doc = yaml.safe_load(CATALOGUE.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise ImaError(f"{CATALOGUE}: cannot read the fault catalogue: {exc}") from exc
    classes = doc.get("classes") if isinstance(doc, dict) else None
    if not isinstance(classes, dict) or not classes:
        raise ImaError(f"{CATALOGUE}: no classes")
    return {name: _load_class(name, c or {}) for name, c in classes.items()}


def get(name: str) -> FaultClass:
    classes = load()
    if name not in classes:
        raise ImaError(f"unknown fault class '{name}' (classes: {', '.join(sorted(classes))})",
                       exit_code=2)
    return classes[name]
