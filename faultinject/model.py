# SPDX-License-Identifier: Apache-2.0
"""What a fault is: its class, its target, when it starts (a time, or a condition resolved to
a time before the run), how long it lasts, and its parameters."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

NS_PER_S = 1_000_000_000


@dataclass(frozen=True)
class Target:
    """Where a fault acts. `node` "*" is every node at once (a common-mode fault); "world" and
    "bus" are the simulated world and the CAN bus itself."""

    node: str
    partition: str | None = None
    process: str | None = None
    port: str | None = None

    def text(self) -> str:
        """partition.port@node2, node2, world ..."""
        inner = self.partition or ""
        if inner and (self.process or self.port):
            inner += "." + (self.process or self.port or "")
        return f"{inner}@{self.node}" if inner else self.node


@dataclass(frozen=True)
class Trigger:
    """When a fault starts: `at_s` (emulated seconds), or a condition the launcher resolves to
    an emulated time before the run: `mode` (the flight control reports this mode on the
    downlink), `after` (another fault of the run, `delay_s` after it starts)."""

    at_s: float | None = None
    mode: str | None = None
    after: str | None = None
    delay_s: float = 0.0

    @property
    def resolved(self) -> bool:
        return self.at_s is not None

    def text(self) -> str:
        if self.mode is not None:
            cond = f"mode={self.mode}"
        elif self.after is not None:
            cond = f"after={self.after}"
        else:
            return f"{self.at_s:g}"
        return cond + (f"+{self.delay_s:g}" if self.delay_s else "")


@dataclass(frozen=True)
class Duration:
    """permanent (from its start on), transient (`length_s`), or intermittent (`on_s` in
    every `period_s`, within `length_s` if given)."""

    kind: str = "permanent"
    length_s: float | None = None
    on_s: float | None = None
    period_s: float | None = None

    def text(self) -> str:
        if self.kind == "transient":
            return f"~{self.length_s:g}"
        if self.kind == "intermittent":
            tail = f"/{self.length_s:g}" if self.length_s is not None else ""
            return f"~{self.on_s:g}/{self.period_s:g}{tail}"
        return ""


@dataclass(frozen=True)
class Fault:
    fid: str
    cls: str
    target: Target
    trigger: Trigger
    duration: Duration = field(default_factory=Duration)
    params: dict[str, Any] = field(default_factory=dict)

    def spec(self) -> str:
        """The short form (faultinject/grammar.py) that gives this fault back."""
        text = f"{self.target.text()}:{self.cls}@{self.trigger.text()}{self.duration.text()}"
        if self.params:
            text += ":" + ",".join(f"{k}={v}" for k, v in self.params.items())
        return text

    def at(self, at_s: float) -> Fault:
        """This fault with its trigger resolved to `at_s`."""
        return replace(self, trigger=Trigger(at_s=at_s))

    @property
    def at_ns(self) -> int:
        assert self.trigger.at_s is not None, f"{self.fid}: trigger not resolved"
        return round(self.trigger.at_s * NS_PER_S)

    @property
    def until_ns(self) -> int | None:
        if self.duration.length_s is None:
            return None
        return self.at_ns + round(self.duration.length_s * NS_PER_S)
