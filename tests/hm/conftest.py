# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the health-monitoring tests: small modules around the test partition hm_rogue
(tests/hm/hm_rogue.c) with the HM tables a case needs, and the trace of a run read back.

The module: two partitions of one program, "healthy" (behaves) and "faulty" (misbehaves as its
Arguments say), with the ports the example's rogue partitions have. Major frame 20 ms; healthy
has the windows [0, 3 ms) and [10, 13 ms), faulty [5, 7 ms): the healthy partition runs right
before and right after every faulty window.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

BUILD = Path(os.environ.get("IMA_BUILD_DIR", Path(__file__).resolve().parents[2] / "build"))
PARTITIONS = BUILD / "partitions"

MAF_NS = 20_000_000
HEALTHY = "healthy"
FAULTY = "faulty"
FAULTY_WINDOW = 2  # WindowIdentifier of the faulty partition's one window
FAULTY_OFFSET_NS = 5_000_000
FAULTY_DURATION_NS = 2_000_000

# ErrorIdentifier and SystemState values (docs/health-monitoring.md).
ERROR_IDS = {
    "DEADLINE_MISSED": 1, "APPLICATION_ERROR": 2, "NUMERIC_ERROR": 3, "ILLEGAL_REQUEST": 4,
    "STACK_OVERFLOW": 5, "MEMORY_VIOLATION": 6, "HARDWARE_FAULT": 7, "POWER_FAIL": 8,
    "WINDOW_OVERRUN": 9, "PARTITION_EXIT": 10,
}
STATES = {"MODULE_INIT": 0, "PARTITION_INIT": 1, "PROCESS": 2, "ERROR_HANDLER": 3}

# An HM table as data: {system state: {error identifier: level or action}}.
Table = dict[int, dict[int, str]]


def _entries(table: Table, entry: str, attribute: str, indent: str) -> list[str]:
    lines = []
    for state, row in table.items():
        lines.append(f'{indent}<System_State_Entry SystemState="{state}">')
        for error, value in row.items():
            lines.append(f'{indent}  <{entry} ErrorIdentifier="{error}" {attribute}="{value}"/>')
        lines.append(f"{indent}</System_State_Entry>")
    return lines


def system_table(table: Table) -> str:
    return "\n".join(["  <System_HM_Table>",
                      *_entries(table, "Error_ID_Level", "ErrorLevel", "    "),
                      "  </System_HM_Table>"])


def module_table(table: Table) -> str:
    return "\n".join(["  <Module_HM_Table>", *_entries(table, "Error_ID_Action", "Action", "    "),
                      "  </Module_HM_Table>"])


def partition_table(table: Table, pid: int = 2, name: str = FAULTY) -> str:
    return "\n".join([f'  <Partition_HM_Table PartitionIdentifier="{pid}" PartitionName="{name}">',
                      *_entries(table, "Error_ID_Action", "Action", "    "),
                      "  </Partition_HM_Table>"])


def _partition(pid: int, name: str, arguments: str, program: str = "hm_rogue",
               system: bool = False) -> str:
    return f"""  <Partition PartitionIdentifier="{pid}" PartitionName="{name}" Criticality="LEVEL_E"
             SystemPartition="{'true' if system else 'false'}">
    <Sampling_Port Name="ROGUE_IN" MaxMessageSize="64" Direction="DESTINATION"
                   RefreshRateSeconds="0.1"/>
    <Queuing_Port Name="ROGUE_OUT" MaxMessageSize="16" Direction="SOURCE" MaxNbMessages="4"/>
    <Queuing_Port Name="ROGUE_Q_IN" MaxMessageSize="16" Direction="DESTINATION" MaxNbMessages="4"/>
    <ima:Linux Executable="{program}" Arguments="{arguments}"/>
  </Partition>"""


def hm_module(faulty: str, *, system: Table | str | None = None, module: Table | str | None = None,
              partition: Table | str | None = None, healthy: str = "none 0",
              program: str = "hm_rogue", system_partition: bool = False) -> str:
    """The text of the test module. `faulty` and `healthy` are hm_rogue's Arguments (the
    faulty partition may run another program with the same ports, such as the example's
    rogue, and be a system partition, which may open files: /proc/self/maps for the fault
    write_port); each table is given as data (a Table), as ready XML, or left out (None)."""
    def render(t, fn):
        if t is None:
            return ""
        return (fn(t) if isinstance(t, dict) else t) + "\n"

    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ARINC_653_Module xmlns:ima="urn:ima-testbed:arinc653-linux:1" ModuleName="hm_case"
                  ModuleVersion="1">
  <ima:Module_Extension Node="node1" TimeMode="emulated"/>
{render(system, system_table)}{render(module, module_table)}{_partition(1, HEALTHY, healthy)}
{_partition(2, FAULTY, faulty, program, system_partition)}
  <Module_Schedule MajorFrameSeconds="0.02">
    <Partition_Schedule PartitionIdentifier="1" PartitionName="{HEALTHY}" PeriodSeconds="0.02"
                        PeriodDurationSeconds="0.006">
      <Window_Schedule WindowIdentifier="1" WindowStartSeconds="0.0" WindowDurationSeconds="0.003"
                       PartitionPeriodStart="true"/>
      <Window_Schedule WindowIdentifier="3" WindowStartSeconds="0.01"
                       WindowDurationSeconds="0.003"/>
    </Partition_Schedule>
    <Partition_Schedule PartitionIdentifier="2" PartitionName="{FAULTY}" PeriodSeconds="0.02"
                        PeriodDurationSeconds="0.002">
      <Window_Schedule WindowIdentifier="{FAULTY_WINDOW}" WindowStartSeconds="0.005"
                       WindowDurationSeconds="0.002" PartitionPeriodStart="true"/>
    </Partition_Schedule>
  </Module_Schedule>
{render(partition, partition_table)}</ARINC_653_Module>
"""


def ske_env() -> dict[str, str]:
    """The environment for an ima-ske a test starts itself: the partitions findable."""
    path = f"{PARTITIONS}:{os.environ.get('IMA_PARTITION_PATH', '')}"
    return dict(os.environ, IMA_PARTITION_PATH=path)


def write_module(folder: Path, name: str, text: str) -> Path:
    path = folder / f"{name}.xml"
    path.write_text(text)
    return path


@dataclass
class Report:
    """One REPORT_APPLICATION_MESSAGE as the trace shows it."""

    t_ns: int
    process: int
    text: str
    index: int  # position of its event in the trace


def reports(events: list[dict], partition: str) -> list[Report]:
    return [Report(e["t_ns"], e["process"], e["text"], i) for i, e in enumerate(events)
            if e["kind"] == "app_message" and e["src"] == partition]


def about(events: list[dict], partition: str) -> list[dict]:
    """Every event the partition wrote, or the SKE wrote about it."""
    return [e for e in events if e["src"] == partition
            or (e["src"] == "ske" and e.get("partition") == partition)]


def hm_events(events: list[dict], partition: str = FAULTY) -> list[tuple[int, dict]]:
    """(trace position, event) of the hm events about a partition."""
    return [(i, e) for i, e in enumerate(events)
            if e["kind"] == "hm" and e["partition"] == partition]


def window_starts(events: list[dict], partition: str) -> list[dict]:
    return [e for e in events if e["kind"] == "window_start" and e["partition"] == partition]


def stats_of(run, partition: str) -> dict:
    (p,) = [p for p in run.stats["partitions"] if p["name"] == partition]
    return p


def context(run) -> str:
    """What to show when an assertion on a run fails."""
    lines = [e for e in run.events if e["kind"] in ("hm", "mode", "partition_exit", "module_stop",
                                                   "start_failed")
             or (e["kind"] == "app_message" and e["src"] == FAULTY)]
    shown = "\n    ".join(str(e) for e in lines[:60])
    return f"\n  ima-ske exit {run.returncode}; stderr: {run.stderr.strip()[-800:]}\n    {shown}"


@pytest.fixture(scope="session")
def hm():
    """The helpers above (module text, trace readers), for the test files of this folder."""
    return sys.modules[__name__]
