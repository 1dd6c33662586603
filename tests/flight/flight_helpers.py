# SPDX-License-Identifier: Apache-2.0
"""Helpers of the flight tests: a node module with a stand-in mission manager, failure dumps."""

from __future__ import annotations

import json
import shutil
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PILOTS = ROOT / "sim" / "pilots"

# The single-node flight's bounds in light turbulence (judged on the truth over the holds);
# a redundant system must fly within the same ones.
LIGHT_BOUNDS = {"alt_err_ft_rms": 12, "alt_err_ft_max": 60, "airspeed_err_kt_rms": 6,
                "airspeed_err_kt_max": 20, "heading_err_deg_rms": 3, "heading_err_deg_max": 12}


def within(summary: dict, bounds: dict) -> list[str]:
    """The bounds a summary breaks (an unjudged value breaks its bound too)."""
    return [f"{k} = {summary.get(k)} > {v}" for k, v in bounds.items()
            if summary.get(k) is None or summary[k] > v]


def mission_node_module(dest: Path, feed_args: str) -> Path:
    """The flight node plus a stand-in mission manager (partition mission_feed) writing
    MISSION targets to nav_fcs in the free part of the major frame."""
    ns = "urn:ima-testbed:arinc653-linux:1"
    ET.register_namespace("ima", ns)
    tree = ET.parse(ROOT / "config" / "nodes" / "rpas_node.xml")
    root = tree.getroot()
    last_part = [i for i, el in enumerate(root) if el.tag == "Partition"][-1]
    part = ET.Element("Partition", PartitionIdentifier="3", PartitionName="mission_feed",
                      Criticality="LEVEL_C", SystemPartition="false", EntryPoint="main")
    ET.SubElement(part, "Sampling_Port", Name="MISSION_OUT", MaxMessageSize="56",
                  Direction="SOURCE", RefreshRateSeconds="0.5")
    ET.SubElement(part, "Process", Name="feed", StackSize="65536")
    ET.SubElement(part, f"{{{ns}}}Linux", Executable="mission_feed", Arguments=feed_args)
    root.insert(last_part + 1, part)
    mem_at = [i for i, el in enumerate(root) if el.tag == "Partition_Memory"][-1]
    mem = ET.Element("Partition_Memory", PartitionIdentifier="3", PartitionName="mission_feed")
    ET.SubElement(mem, "Memory_Requirements", Type="DATA", SizeBytes="0x2000000",
                  Access="READ_WRITE")
    root.insert(mem_at + 1, mem)
    sched = root.find("Module_Schedule")
    ps = ET.SubElement(sched, "Partition_Schedule", PartitionIdentifier="3",
                       PartitionName="mission_feed", PeriodSeconds="0.05",
                       PeriodDurationSeconds="0.005")
    ET.SubElement(ps, "Window_Schedule", WindowIdentifier="4", WindowStartSeconds="0.03",
                  WindowDurationSeconds="0.005", PartitionPeriodStart="true")
    table = root.find("Connection_Table")
    ch = ET.SubElement(table, "Channel", ChannelIdentifier="9", ChannelName="mission")
    src = ET.SubElement(ch, "Source")
    ET.SubElement(src, "Standard_Partition", PartitionIdentifier="3",
                  PartitionName="mission_feed", PortName="MISSION_OUT")
    dst = ET.SubElement(ch, "Destination")
    ET.SubElement(dst, "Standard_Partition", PartitionIdentifier="2", PartitionName="nav_fcs",
                  PortName="MISSION_IN")
    tree.write(dest, encoding="UTF-8", xml_declaration=True)
    return dest


def dump(f) -> str:
    """What a failing assertion shows: the summary without the long lists."""
    s = {k: v for k, v in f.summary.items() if k not in ("hm_event_list",)}
    return json.dumps(s, indent=1)


def host_stalls(run_dir) -> list[dict]:
    """The SKE's CPU-budget overruns in the run's node traces. The partitions of these flights
    use a tiny part of their budgets (io some 20 µs of CPU per 5 ms window); one that still
    overran was stalled in the kernel on the host's account (direct reclaim, a preempted
    virtual CPU), not by anything under test. A run with one is flown again, once."""
    out = []
    for trace in sorted(Path(run_dir).glob("node*.jsonl")):
        with open(trace) as f:
            for line in f:
                if '"kind":"overrun"' in line and '"cause":"cpu_budget"' in line:
                    out.append(dict(json.loads(line), trace=trace.name))
    return out


def fly_unless_host_stalled(fly, run_dir, name: str):
    """`fly()`, which flies into run_dir; once more, into a fresh run_dir, if the host stalled a
    partition past its CPU budget (host_stalls), with a warning that names the stall. Returns
    the last flight's result; a stall in that one is the tests' to judge."""
    result = fly()
    stalls = host_stalls(run_dir)
    if stalls:
        warnings.warn(f"{name}: flown again, the host stalled a partition past its CPU "
                      f"budget: {stalls[0]}", stacklevel=2)
        shutil.rmtree(run_dir)
        result = fly()
    return result
