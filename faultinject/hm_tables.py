# SPDX-License-Identifier: Apache-2.0
"""The health-monitor decisions a module's tables prescribe, read from the module XML the node
ran and computed here, from ARINC 653 Part 1 and docs/health-monitoring.md, without the
health-monitor code the oracle checks: the System HM table gives the level, the Module or
Partition HM table the action, PROCESS level goes to an error handler or, with none, to the
partition level (2.4.2.3), and a fault during initialisation cannot be ignored."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

ERRORS = {1: "DEADLINE_MISSED", 2: "APPLICATION_ERROR", 3: "NUMERIC_ERROR", 4: "ILLEGAL_REQUEST",
          5: "STACK_OVERFLOW", 6: "MEMORY_VIOLATION", 7: "HARDWARE_FAULT", 8: "POWER_FAIL",
          9: "WINDOW_OVERRUN", 10: "PARTITION_EXIT"}
STATES = {0: "MODULE_INIT", 1: "PARTITION_INIT", 2: "PROCESS", 3: "ERROR_HANDLER"}
_TIMING = ("WINDOW_OVERRUN", "DEADLINE_MISSED")  # IGNORE by default: a timing error
# Errors after which the failed context cannot go on (a fault signal, an end).
_FATAL = ("NUMERIC_ERROR", "ILLEGAL_REQUEST", "STACK_OVERFLOW", "MEMORY_VIOLATION",
          "HARDWARE_FAULT", "PARTITION_EXIT")


@dataclass
class Tables:
    level: dict[tuple[str, str], str] = field(default_factory=dict)  # (state, error) -> level
    module: dict[tuple[str, str], str] = field(default_factory=dict)  # -> module action
    partition: dict[str, dict[tuple[str, str], str]] = field(default_factory=dict)


def _entries(elem, attr: str) -> dict[tuple[str, str], str]:
    out = {}
    if elem is None:
        return out
    for st in elem.findall("System_State_Entry"):
        state = STATES.get(int(st.get("SystemState")), "?")
        for e in st:
            out[(state, ERRORS.get(int(e.get("ErrorIdentifier")), "?"))] = e.get(attr)
    return out


def read(module: Path) -> Tables:
    root = ET.parse(module).getroot()
    t = Tables(level=_entries(root.find("System_HM_Table"), "ErrorLevel"),
               module=_entries(root.find("Module_HM_Table"), "Action"))
    for pt in root.findall("Partition_HM_Table"):
        t.partition[pt.get("PartitionName")] = _entries(pt, "Action")
    return t


def expected(t: Tables, partition: str, state: str, error: str) -> set[tuple[str, str]]:
    """The (level, action) pairs the tables allow for this error: one, or two at PROCESS
    level (the error handler's, or the partition level's when the partition has none)."""
    level = t.level.get((state, error), "PARTITION")
    if level == "MODULE":
        return {("MODULE", t.module.get((state, error), "IGNORE"))}
    default = "IGNORE" if error in _TIMING else "IDLE"
    action = t.partition.get(partition, {}).get((state, error), default)
    if action == "IGNORE" and state == "PARTITION_INIT" and error in _FATAL:
        action = "IDLE"  # nothing could run: docs/health-monitoring.md, IGNORE
    at_partition = ("PARTITION", action)
    if level == "PROCESS":
        return {("PROCESS", "ERROR_HANDLER"), at_partition}
    return {at_partition}
