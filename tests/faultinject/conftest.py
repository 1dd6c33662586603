# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the fault-injection tests: a small module whose partition "faulty" (the rogue
example program, behaving) is made to misbehave by `ima-ske --fault`, beside the example's
producer and consumer, and a "sink" that reads nothing; the trace of a run read back.

Major frame 50 ms. Windows: producer [0, 5 ms), consumer [10, 15 ms), faulty [20, 22 ms),
sink [30, 31 ms). faulty's one process "rogue" is released every 50 ms at 20 ms into the frame
(its first window), with its deadline at its next release. Channels: producer.SP_STATE ->
consumer.SP_STATE_IN and faulty.ROGUE_IN (sampling); producer.QP_CMD -> consumer.QP_CMD_IN and
faulty.ROGUE_OUT -> sink.ROGUE_Q_IN (queuing; nobody reads the sink's).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build"))
SKE = BUILD / "ske" / "ima-ske"
PARTITIONS = BUILD / "partitions"

MAF_NS = 50_000_000
FAULTY = "faulty"
FAULTY_OFFSET_NS = 20_000_000
FAULTY_DURATION_NS = 2_000_000

ERROR_IDS = {
    "DEADLINE_MISSED": 1, "APPLICATION_ERROR": 2, "NUMERIC_ERROR": 3, "ILLEGAL_REQUEST": 4,
    "STACK_OVERFLOW": 5, "MEMORY_VIOLATION": 6, "HARDWARE_FAULT": 7, "POWER_FAIL": 8,
    "WINDOW_OVERRUN": 9, "PARTITION_EXIT": 10,
}

# An HM table as data: {system state: {error name: level or action}}.
Table = dict[int, dict[str, str]]


def _entries(table: Table, entry: str, attribute: str) -> list[str]:
    lines = []
    for state, row in table.items():
        lines.append(f'    <System_State_Entry SystemState="{state}">')
        for error, value in row.items():
            lines.append(f'      <{entry} ErrorIdentifier="{ERROR_IDS[error]}" {attribute}="{value}"/>')
        lines.append("    </System_State_Entry>")
    return lines


def _rogue(pid: int, name: str, arguments: str, system: bool) -> str:
    return f"""  <Partition PartitionIdentifier="{pid}" PartitionName="{name}" Criticality="LEVEL_E"
             SystemPartition="{'true' if system else 'false'}">
    <Sampling_Port Name="ROGUE_IN" MaxMessageSize="64" Direction="DESTINATION" RefreshRateSeconds="0.1"/>
    <Queuing_Port Name="ROGUE_OUT" MaxMessageSize="16" Direction="SOURCE" MaxNbMessages="4"/>
    <Queuing_Port Name="ROGUE_Q_IN" MaxMessageSize="16" Direction="DESTINATION" MaxNbMessages="4"/>
    <Process Name="rogue" StackSize="65536"/>
    <ima:Linux Executable="rogue" Arguments="{arguments}"/>
  </Partition>"""


def module(*, faulty: str = "none 100000", system: Table | None = None,
           module_table: Table | None = None, partition: Table | None = None,
           faulty_system: bool = False, faulty_memory: bool = True) -> str:
    """The text of the test module; `faulty` is the rogue's Arguments (add "handler" for an
    error handler that STARTs the failed process again); without `faulty_memory` the faulty
    partition has no Partition_Memory, hence no memory limit."""
    tables = ""
    if system:
        tables += "\n".join(["  <System_HM_Table>", *_entries(system, "Error_ID_Level", "ErrorLevel"),
                             "  </System_HM_Table>"]) + "\n"
    if module_table:
        tables += "\n".join(["  <Module_HM_Table>", *_entries(module_table, "Error_ID_Action", "Action"),
                             "  </Module_HM_Table>"]) + "\n"
    ptable = ""
    if partition:
        ptable = "\n".join([f'  <Partition_HM_Table PartitionIdentifier="3" PartitionName="{FAULTY}">',
                            *_entries(partition, "Error_ID_Action", "Action"),
                            "  </Partition_HM_Table>"]) + "\n"
    memory = "".join(f"""  <Partition_Memory PartitionIdentifier="{i}" PartitionName="{n}">
    <Memory_Requirements Type="DATA" SizeBytes="0x4000000" Access="READ_WRITE"/>
  </Partition_Memory>
""" for i, n in ((1, "producer"), (2, "consumer"), (3, FAULTY), (4, "sink"))
                 if faulty_memory or n != FAULTY)

    def sched(pid: int, name: str, start: float, dur: float) -> str:
        return f"""    <Partition_Schedule PartitionIdentifier="{pid}" PartitionName="{name}" PeriodSeconds="0.05">
      <Window_Schedule WindowIdentifier="{pid}" WindowStartSeconds="{start}" WindowDurationSeconds="{dur}"
                       PartitionPeriodStart="true"/>
    </Partition_Schedule>
"""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ARINC_653_Module xmlns:ima="urn:ima-testbed:arinc653-linux:1" ModuleName="fi_case" ModuleVersion="1">
  <ima:Module_Extension Node="node1" TimeMode="emulated"/>
{tables}  <Partition PartitionIdentifier="1" PartitionName="producer" Criticality="LEVEL_B" SystemPartition="false">
    <Sampling_Port Name="SP_STATE" MaxMessageSize="64" Direction="SOURCE" RefreshRateSeconds="0.1"/>
    <Queuing_Port Name="QP_CMD" MaxMessageSize="32" Direction="SOURCE" MaxNbMessages="8"/>
    <Process Name="produce" StackSize="65536"/>
    <ima:Linux Executable="ex_producer"/>
  </Partition>
  <Partition PartitionIdentifier="2" PartitionName="consumer" Criticality="LEVEL_B" SystemPartition="false">
    <Sampling_Port Name="SP_STATE_IN" MaxMessageSize="64" Direction="DESTINATION" RefreshRateSeconds="0.1"/>
    <Queuing_Port Name="QP_CMD_IN" MaxMessageSize="32" Direction="DESTINATION" MaxNbMessages="16"/>
    <Process Name="sample" StackSize="65536"/>
    <Process Name="receive" StackSize="65536"/>
    <ima:Linux Executable="ex_consumer"/>
  </Partition>
{_rogue(3, FAULTY, faulty, faulty_system)}
{_rogue(4, "sink", "none 100000", False)}
{memory}  <Module_Schedule MajorFrameSeconds="0.05">
{sched(1, "producer", 0.0, 0.005)}{sched(2, "consumer", 0.01, 0.005)}{sched(3, FAULTY, 0.02, 0.002)}{sched(4, "sink", 0.03, 0.001)}  </Module_Schedule>
{ptable}  <Connection_Table>
    <Channel ChannelIdentifier="1" ChannelName="state">
      <Source><Standard_Partition PartitionIdentifier="1" PartitionName="producer" PortName="SP_STATE"/></Source>
      <Destination><Standard_Partition PartitionIdentifier="2" PartitionName="consumer" PortName="SP_STATE_IN"/></Destination>
      <Destination><Standard_Partition PartitionIdentifier="3" PartitionName="{FAULTY}" PortName="ROGUE_IN"/></Destination>
    </Channel>
    <Channel ChannelIdentifier="2" ChannelName="commands">
      <Source><Standard_Partition PartitionIdentifier="1" PartitionName="producer" PortName="QP_CMD"/></Source>
      <Destination><Standard_Partition PartitionIdentifier="2" PartitionName="consumer" PortName="QP_CMD_IN"/></Destination>
    </Channel>
    <Channel ChannelIdentifier="3" ChannelName="flood">
      <Source><Standard_Partition PartitionIdentifier="3" PartitionName="{FAULTY}" PortName="ROGUE_OUT"/></Source>
      <Destination><Standard_Partition PartitionIdentifier="4" PartitionName="sink" PortName="ROGUE_Q_IN"/></Destination>
    </Channel>
  </Connection_Table>
</ARINC_653_Module>
"""


@dataclass
class Run:
    """One ima-ske run: exit status, standard error, the trace's events."""

    returncode: int
    stderr: str
    trace: bytes = b""
    events: list[dict] = field(default_factory=list)

    def of(self, kind: str, **match) -> list[dict]:
        return [e for e in self.events if e["kind"] == kind
                and all(e.get(k) == v for k, v in match.items())]

    def index(self, event: dict) -> int:
        return self.events.index(event)

    def context(self) -> str:
        shown = [e for e in self.events if e["kind"] in ("fault", "hm", "mode", "partition_exit",
                                                          "overrun", "start_failed", "module_stop")]
        lines = "\n    ".join(json.dumps(e) for e in shown[:60])
        return f"\n  exit {self.returncode}; stderr: {self.stderr.strip()[-600:]}\n    {lines}"


def ske_env() -> dict[str, str]:
    return dict(os.environ, IMA_PARTITION_PATH=f"{PARTITIONS}:{os.environ.get('IMA_PARTITION_PATH', '')}")


@pytest.fixture
def run_fi(tmp_path):
    """run_fi(module_text, frames, *options) -> Run."""
    counter = iter(range(1000))

    def run(text: str, frames: int, *options: str, timeout: float = 60) -> Run:
        n = next(counter)
        path = tmp_path / f"m{n}.xml"
        path.write_text(text)
        trace = tmp_path / f"t{n}.jsonl"
        p = subprocess.run([str(SKE), "--frames", str(frames), "--trace", str(trace), *options,
                            str(path)], capture_output=True, text=True, timeout=timeout,
                           env=ske_env())
        data = trace.read_bytes() if trace.exists() else b""
        return Run(p.returncode, p.stderr, data, [json.loads(x) for x in data.splitlines()])

    return run


@pytest.fixture(scope="session")
def fi():
    """The helpers above, for the test files of this folder."""
    if not SKE.is_file():
        pytest.fail(f"{SKE} is not built: run ./ima test (it builds first)")
    return sys.modules[__name__]
