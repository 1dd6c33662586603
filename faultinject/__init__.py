# SPDX-License-Identifier: Apache-2.0
"""faultinject: the fault model (what a fault is, its short and YAML forms), the catalogue of
fault classes, the plan that turns a run's faults into the injectors' command lines, and the
oracles that judge a run against its golden run."""

from faultinject.model import Duration, Fault, Target, Trigger

__all__ = ["Duration", "Fault", "Target", "Trigger"]
