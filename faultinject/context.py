# SPDX-License-Identifier: Apache-2.0
"""What the oracles judge a run with: its records, its golden run's, the plan of its faults,
the system it ran."""

from __future__ import annotations

from dataclasses import dataclass

from faultinject import catalogue
from faultinject.plan import Plan
from faultinject.traces import RunTraces, fcs_choices


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

    def _mode_at(self, traces: RunTraces, field: str, t_ns: int) -> str | None:
        return fcs_choices(field).get(traces.fcs_at(field, t_ns))

    def asked_mode(self, t_ns: int) -> str | None:
        """The mode the pilot asks for at t_ns, from the golden run's FCS heartbeats (the
        run's when there is none): DIRECT, AUTOPILOT, MISSION, or None before any."""
        return self._mode_at(self.golden or self.run, "FCS_REQ_MODE", t_ns)

    def flown_mode(self, t_ns: int) -> str | None:
        """The mode the flight control flies at t_ns in this run (an earlier fault of the run
        may have changed it): its last heartbeat at or before t_ns."""
        return self._mode_at(self.run, "FCS_MODE", t_ns)

    def fault_class(self, fault) -> catalogue.FaultClass:
        """The catalogue's class of a fault, with the expectations of its case (the mode asked
        and flown at the injection, the target partition and port, common mode)."""
        fc = catalogue.get(fault.cls)
        if not fc.cases:
            return fc
        at = None if fault.trigger.at_s is None else fault.at_ns
        return fc.case(asked=None if at is None else self.asked_mode(at),
                       flown=None if at is None else self.flown_mode(at),
                       partition=fault.target.partition, port=fault.target.port,
                       common_mode=fault.target.node == "*")
