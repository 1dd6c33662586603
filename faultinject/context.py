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

    def asked_mode(self, t_ns: int | None) -> str | None:
        """The mode the pilot asks for at t_ns, from the golden run's FCS heartbeats (the
        run's when there is none): DIRECT, AUTOPILOT, MISSION, or None before any."""
        if t_ns is None:
            return None
        names = fcs_choices("FCS_REQ_MODE")
        asked = None
        for t, _k, d in (self.golden or self.run).fcs_status:
            if t > t_ns:
                break
            asked = names.get(d.get("FCS_REQ_MODE"))
        return asked

    def fault_class(self, fault) -> catalogue.FaultClass:
        """The catalogue's class of a fault, with the expectations of its case (the mode asked
        at the injection, the target partition, common mode)."""
        fc = catalogue.get(fault.cls)
        if not fc.cases:
            return fc
        asked = None if fault.trigger.at_s is None else self.asked_mode(fault.at_ns)
        return fc.case(asked, fault.target.partition, fault.target.node == "*")
