# SPDX-License-Identifier: Apache-2.0
"""What the oracles judge a run with: its records, its golden run's, the plan of its faults,
the system it ran."""

from __future__ import annotations

from dataclasses import dataclass

from faultinject.plan import Plan
from faultinject.traces import RunTraces


@dataclass
class Context:
    run: RunTraces
    golden: RunTraces | None
    plan: Plan
    system: object  # ima.deploy.System
    duration_s: float

    @property
    def redundant(self) -> bool:
        """More than one replica of the flight control: the catalogue's `redundant` variant."""
        return len(self.system.nodes) > 1 and bool(self.system.replicated)

    @property
    def node_names(self) -> list[str]:
        return [n.name for n in self.system.nodes]
