# SPDX-License-Identifier: Apache-2.0
"""The fault spec every injector reads (faultinject/include/fi/spec.h), in Python: the same
grammar, limits, error messages and spells in time as the C parser (faultinject/src/spec.c).

    CLASS:fid=ID,at=TIME[,until=TIME][,period=TIME,on=TIME][,KEY=VALUE...]

TIME is a number with a unit: ns (or none), us, ms, s. Permanent: no `until`, no `period`;
transient: `until`, active in [at, until); intermittent: `period` and `on`, active in
[at + k*period, at + k*period + on), up to `until` if given.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from ima.errors import ImaError

NAME_MAX = 32  # a class name, with the C string's NUL
ID_MAX = 16
KEY_MAX = 24
VALUE_MAX = 104
MAX_PARAMS = 12
SPEC_MAX = 1024
NEVER = (1 << 63) - 1  # INT64_MAX, FI_NEVER

_UNITS = {"": 1.0, "ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
# What strtod reads of a decimal number (the C parser takes any strtod number; decimals are
# what a user writes), then the unit.
_TIME = re.compile(r"([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)(.*)", re.S)
_ID = re.compile(r"[A-Za-z0-9_-]+")
_NAME = re.compile(r"[a-z0-9_]+")


class FaultSpecError(ImaError):
    """A fault spec that does not parse: one line, exit code 2 (a usage error)."""

    def __init__(self, message: str) -> None:
        super().__init__(message, exit_code=2)


def parse_time(text: str) -> int | None:
    """"123", "123ns", "5us", "20ms", "1.5s" -> nanoseconds, or None (fi_parse_time)."""
    m = _TIME.fullmatch(text)
    if not m or m.group(2) not in _UNITS:
        return None
    v = float(m.group(1))
    if not math.isfinite(v) or v < 0:
        return None
    t = v * _UNITS[m.group(2)]
    if t >= 9.2e18:
        return None
    return math.floor(t + 0.5)  # llround of a non-negative value


@dataclass(frozen=True)
class FaultSpec:
    """One parsed fault (fi_spec_t). `params` keeps the class's KEY=VALUE pairs in order."""

    cls: str
    fid: str
    at_ns: int
    until_ns: int = NEVER
    period_ns: int = 0
    on_ns: int = 0
    duration: str = "permanent"  # "permanent", "transient", "intermittent"
    params: dict = field(default_factory=dict)
    text: str = ""

    def spell(self, t_ns: int) -> int:
        """The active spell at t (k >= 0; always 0 unless intermittent), or -1 (fi_spec_spell)."""
        if t_ns < self.at_ns or t_ns >= self.until_ns:
            return -1
        if self.duration != "intermittent":
            return 0
        k = (t_ns - self.at_ns) // self.period_ns
        return k if t_ns - (self.at_ns + k * self.period_ns) < self.on_ns else -1

    def spell_start(self, k: int) -> int:
        return self.at_ns + k * self.period_ns if self.duration == "intermittent" else self.at_ns

    def spell_end(self, k: int) -> int:
        """When spell k stops (NEVER for a permanent fault)."""
        if self.duration == "intermittent":
            return min(self.spell_start(k) + self.on_ns, self.until_ns)
        return self.until_ns

    def end(self) -> int:
        """When the fault stops for good (NEVER for a permanent or endless intermittent one)."""
        return self.until_ns

    def next_change(self, t_ns: int) -> int:
        """The first instant after t at which the fault starts or stops a spell (NEVER: none)."""
        if t_ns < self.at_ns:
            return self.at_ns
        if t_ns >= self.until_ns:
            return NEVER
        if self.duration != "intermittent":
            return self.until_ns
        k = (t_ns - self.at_ns) // self.period_ns
        start = self.at_ns + k * self.period_ns
        if t_ns < start + self.on_ns:  # in spell k: its end
            return min(start + self.on_ns, self.until_ns)
        nxt = start + self.period_ns  # between spells: the next start, if any
        return nxt if nxt < self.until_ns else NEVER


def parse(text: str) -> FaultSpec:
    """Parses one spec; FaultSpecError with the C parser's message when it is bad."""
    if text is None or len(text.encode()) >= SPEC_MAX:
        raise FaultSpecError(f"fault spec missing or longer than {SPEC_MAX - 1} characters")
    cls, colon, rest = text.partition(":")
    if not _NAME.fullmatch(cls) or len(cls) >= NAME_MAX:
        raise FaultSpecError(f"'{cls}': a fault class is 1 to {NAME_MAX - 1} characters of "
                             "a-z 0-9 _")
    fid = ""
    at = until = period = on = None
    params: dict[str, str] = {}
    for kv in (t for t in rest.split(",") if t) if colon else ():  # strtok skips empty fields
        key, eq, val = kv.partition("=")
        if not eq:
            raise FaultSpecError(f"'{kv}': expected KEY=VALUE")
        if key == "fid":
            if not _ID.fullmatch(val) or len(val) >= ID_MAX:
                raise FaultSpecError(f"fid '{val}': 1 to {ID_MAX - 1} characters of A-Z a-z "
                                     "0-9 _ -")
            fid = val
            continue
        if key in ("at", "from", "until", "period", "on"):
            ns = parse_time(val)
            if ns is None:
                raise FaultSpecError(f"bad time '{val}' for '{key}'")
            if key in ("at", "from"):
                at = ns
            elif key == "until":
                until = ns
            elif key == "period":
                period = ns
            else:
                on = ns
            continue
        if len(params) == MAX_PARAMS:
            raise FaultSpecError(f"more than {MAX_PARAMS} parameters")
        if not key or len(key) >= KEY_MAX or len(val) >= VALUE_MAX:
            raise FaultSpecError(f"parameter '{key}' too long or empty")
        if key in params:
            raise FaultSpecError(f"parameter '{key}' given twice")
        params[key] = val
    if not fid:
        raise FaultSpecError(f"{cls}: fid=ID is required")
    if at is None:
        raise FaultSpecError(f"{cls}: at=TIME is required")
    if until is not None and until <= at:
        raise FaultSpecError(f"{cls}: until must be after at")
    if (period is None) != (on is None):
        raise FaultSpecError(f"{cls}: an intermittent fault has both period and on")
    if period is not None:
        if period <= 0 or on <= 0 or on > period:
            raise FaultSpecError(f"{cls}: needs 0 < on <= period")
        duration = "intermittent"
    else:
        duration = "permanent" if until is None else "transient"
    return FaultSpec(cls=cls, fid=fid, at_ns=at, until_ns=NEVER if until is None else until,
                     period_ns=period or 0, on_ns=on or 0, duration=duration, params=params,
                     text=text)


def param_float(spec: FaultSpec, key: str, default: float | None = None) -> float | None:
    """A parameter as a finite number; default when absent; FaultSpecError when not a number."""
    v = spec.params.get(key)
    if v is None:
        return default
    m = _TIME.fullmatch(v)
    x = float(m.group(1)) if m and not m.group(2) else math.nan
    if not math.isfinite(x):
        raise FaultSpecError(f"{spec.cls}:{spec.fid}: {key}={v} is not a number")
    return x
