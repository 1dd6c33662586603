# SPDX-License-Identifier: Apache-2.0
"""The rogues example (config/examples/rogues.xml; docs/health-monitoring.md, "Worked example"):
three healthy partitions beside thirteen rogue partitions (partitions/rogues/rogue.c), each
doing one bad thing at a known release, run for 400 major frames with `./ima run`.

- Every error is decided as the module's own HM tables say: the expectations are read from
  the XML (levels, actions, which rogue has an error handler), not written here. What each
  rogue's FAULT causes is rogue.c's behaviour, in ROGUE_ERRORS; each decision lies in a window
  of its partition (the SKE's own detections at the window's end).
- The flood is no error of the sender: from its second flooding release on, every message it
  sends overflows the destination nobody reads (`port` overflow events).
- The healthy partitions cannot tell: their window starts and every message they report are
  identical to a run of the same module in which every rogue behaves (Arguments "none").
- Two runs write byte-identical traces (emulated time).

A run in which the host stalled a partition that does not spin past its CPU budget (the
flood, for one, uses some 20 µs of its 1 ms window on average) is run again, once, by the
flight tests' rule (tests/flight/flight_helpers.py: fly_unless_host_stalled).

The rogues socket, fork and kill are stopped by the partitions' seccomp sandbox
(ILLEGAL_REQUEST); without it, kill takes the SKE itself down.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flight"))  # the flight tests' helpers
from flight_helpers import fly_unless_host_stalled  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
MODULE = ROOT / "config" / "examples" / "rogues.xml"
FRAMES = 400
HEALTHY = ("producer", "consumer", "monitor")
NODE = "node1"  # its trace is NODE.jsonl, as a flight's node's (flight_helpers.host_stalls)

# The error each FAULT of rogue.c causes (None: none of its own).
ROGUE_ERRORS = {
    "segv": "MEMORY_VIOLATION",
    "write_port": "MEMORY_VIOLATION",  # a write to its destination port's read-only mapping
    "divide": "NUMERIC_ERROR",
    "stack": "STACK_OVERFLOW",
    "spin": "WINDOW_OVERRUN",
    "alloc": "APPLICATION_ERROR",  # malloc fails at the memory limit; it raises the error
    "socket": "ILLEGAL_REQUEST",  # denied by the sandbox
    "fork": "ILLEGAL_REQUEST",
    "kill": "ILLEGAL_REQUEST",
    "apex": "ILLEGAL_REQUEST",  # an invalid address given to SEND_QUEUING_MESSAGE
    "app_error": "APPLICATION_ERROR",
    "deadline": "DEADLINE_MISSED",
    "flood": None,  # the destination's overflow is a port event, not an error of the sender
    "none": None,
}
ERROR_IDS = {"DEADLINE_MISSED": 1, "APPLICATION_ERROR": 2, "NUMERIC_ERROR": 3,
             "ILLEGAL_REQUEST": 4, "STACK_OVERFLOW": 5, "MEMORY_VIOLATION": 6,
             "HARDWARE_FAULT": 7, "POWER_FAIL": 8, "WINDOW_OVERRUN": 9, "PARTITION_EXIT": 10}
STATES = {"MODULE_INIT": 0, "PARTITION_INIT": 1, "PROCESS": 2, "ERROR_HANDLER": 3}
# The errors the example is there to show.
SHOWN = {"MEMORY_VIOLATION", "NUMERIC_ERROR", "STACK_OVERFLOW", "DEADLINE_MISSED",
         "ILLEGAL_REQUEST", "APPLICATION_ERROR"}


# ---- the module's HM tables, read from the XML ---------------------------------------------

def local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def children(node, name: str):
    return [c for c in node if local(c.tag) == name]


@dataclass
class Tables:
    level: dict[tuple[int, int], str]  # (state, error) -> ErrorLevel
    module: dict[tuple[int, int], str]  # (state, error) -> Action
    partition: dict[str, dict[tuple[int, int], str]]  # partition -> (state, error) -> Action
    arguments: dict[str, list[str]]  # partition -> its program's Arguments, split

    def decide(self, partition: str, state: int, error: int) -> tuple[str, str]:
        """(level, action) by docs/health-monitoring.md: defaults for what a table leaves out;
        PROCESS level needs the partition's error handler, else the partition level decides."""
        level = self.level.get((state, error), "PARTITION")
        if level == "PROCESS":
            if "handler" in self.arguments.get(partition, [])[2:]:
                return "PROCESS", "ERROR_HANDLER"
            level = "PARTITION"
        if level == "MODULE":
            return "MODULE", self.module.get((state, error), "IGNORE")
        timing = (ERROR_IDS["WINDOW_OVERRUN"], ERROR_IDS["DEADLINE_MISSED"])
        default = "IGNORE" if error in timing else "IDLE"
        return "PARTITION", self.partition.get(partition, {}).get((state, error), default)


def entries(table, entry: str, attribute: str) -> dict[tuple[int, int], str]:
    out = {}
    for sse in children(table, "System_State_Entry"):
        for e in children(sse, entry):
            out[(int(sse.get("SystemState")), int(e.get("ErrorIdentifier")))] = e.get(attribute)
    return out


def read_tables(path: Path) -> Tables:
    root = ET.parse(path).getroot()
    level, module, partition, arguments = {}, {}, {}, {}
    for t in children(root, "System_HM_Table"):
        level.update(entries(t, "Error_ID_Level", "ErrorLevel"))
    for t in children(root, "Module_HM_Table"):
        module.update(entries(t, "Error_ID_Action", "Action"))
    for t in children(root, "Partition_HM_Table"):
        partition[t.get("PartitionName")] = entries(t, "Error_ID_Action", "Action")
    for p in children(root, "Partition"):
        (linux,) = [c for c in p if local(c.tag) == "Linux"]
        if linux.get("Executable") == "rogue":
            arguments[p.get("PartitionName")] = linux.get("Arguments", "").split()
    return Tables(level, module, partition, arguments)


@dataclass
class Channel:
    name: str
    source: tuple[str, str]  # (partition, port)
    destinations: list[tuple[str, str]]


def read_channels(path: Path) -> list[Channel]:
    root = ET.parse(path).getroot()
    out = []
    for table in children(root, "Connection_Table"):
        for ch in children(table, "Channel"):
            ends = {}
            for side in ("Source", "Destination"):
                ends[side] = [(e.get("PartitionName"), e.get("PortName"))
                              for node in children(ch, side) for e in node]
            (source,) = ends["Source"]
            out.append(Channel(ch.get("ChannelName"), source, ends["Destination"]))
    return out


def queue_depth(path: Path, partition: str, port: str) -> int:
    root = ET.parse(path).getroot()
    (p,) = [p for p in children(root, "Partition") if p.get("PartitionName") == partition]
    (q,) = [q for q in children(p, "Queuing_Port") if q.get("Name") == port]
    return int(q.get("MaxNbMessages"))


# ---- runs ----------------------------------------------------------------------------------

@dataclass
class Run:
    returncode: int
    stderr: str
    trace: bytes

    @property
    def events(self) -> list[dict]:
        return [json.loads(line) for line in self.trace.splitlines()]


def ima_run(module: Path, cwd: Path) -> Run:
    cwd.mkdir(parents=True, exist_ok=True)
    p = subprocess.run([str(ROOT / "ima"), "run", str(module), "--frames", str(FRAMES),
                        "--trace", f"{NODE}.jsonl"], cwd=cwd,
                       env=dict(os.environ, IMA_SKIP_BUILD="1"), capture_output=True, text=True,
                       timeout=180)
    trace = cwd / f"{NODE}.jsonl"
    return Run(p.returncode, p.stderr, trace.read_bytes() if trace.exists() else b"")


def behaving(path: Path) -> str:
    """The module's text with every rogue's Arguments replaced by "none"."""
    return re.sub(r'(Executable="rogue"\s+Arguments=")[^"]*"', r'\1none"', path.read_text())


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Run]:
    folder = tmp_path_factory.mktemp("rogues")
    quiet = folder / "behaving.xml"
    quiet.write_text(behaving(MODULE))
    arguments = read_tables(MODULE).arguments
    assert quiet.read_text().count('Arguments="none"') == len(arguments)
    # the rogue whose overruns the tests judge; any other partition's is the host's
    spinning = frozenset((NODE, name) for name, args in arguments.items() if args[0] == "spin")
    assert spinning

    def run(module: Path, cwd: Path) -> Run:
        return fly_unless_host_stalled(lambda: ima_run(module, cwd), cwd, module.name, spinning)

    return {"rogues": run(MODULE, folder / "a"), "again": run(MODULE, folder / "b"),
            "behaving": run(quiet, folder / "c")}


def describe(run: Run) -> str:
    stop = [e for e in run.events if e["kind"] == "module_stop"]
    return f"\n  exit {run.returncode}, module_stop {stop}, stderr: {run.stderr.strip()[-600:]}"


# ---- tests ---------------------------------------------------------------------------------

def test_rogues_run_to_the_end(runs):
    for name in ("rogues", "again", "behaving"):
        run = runs[name]
        assert run.returncode == 0, f"{name} run" + describe(run)
        (stop,) = [e for e in run.events if e["kind"] == "module_stop"]
        assert (stop["frames"], stop["reason"]) == (FRAMES, "frames"), stop


def test_every_error_is_decided_as_the_tables_say(runs):
    tables = read_tables(MODULE)
    events = runs["rogues"].events
    hm = [e for e in events if e["kind"] == "hm"]
    assert hm, describe(runs["rogues"])
    wrong = []
    for e in hm:
        expected = tables.decide(e["partition"], STATES[e["state"]], ERROR_IDS[e["error"]])
        if (e["level"], e["action"]) != expected:
            got = (e["level"], e["action"])
            wrong.append((e["partition"], e["error"], e["state"], got, expected))
    assert not wrong, f"decisions (partition, error, state, got, expected): {wrong}"
    assert not [e for e in hm if e["partition"] in HEALTHY], "a healthy partition had an error"


def test_every_decision_lies_in_a_window_of_its_partition(runs):
    """A partition's error is decided at once, at its time inside the window; what the SKE
    detects itself (an overrun, an exit) at the window's end."""
    events = runs["rogues"].events
    (start,) = [e for e in events if e["kind"] == "module_start"]
    maf = start["major_frame_ns"]
    windows = {}
    for w in start["windows"]:
        windows.setdefault(w["partition"], []).append((w["offset_ns"], w["duration_ns"]))
    wrong = []
    for e in events:
        if e["kind"] != "hm":
            continue
        t = e["t_ns"] % maf
        inside = [(o, d) for o, d in windows[e["partition"]] if o <= t <= o + d]
        if e["error"] in ("WINDOW_OVERRUN", "PARTITION_EXIT"):
            ok = any(t == o + d for o, d in inside)
        else:
            ok = bool(inside)
        if not ok:
            wrong.append((e["partition"], e["error"], e["t_ns"]))
    assert not wrong, f"decisions outside their windows (partition, error, t_ns): {wrong}"


def test_each_rogue_causes_its_error(runs):
    tables = read_tables(MODULE)
    events = runs["rogues"].events
    errors = {}
    for e in events:
        if e["kind"] == "hm":
            errors.setdefault(e["partition"], set()).add(e["error"])
    expected = {name: {ROGUE_ERRORS[args[0]]} for name, args in tables.arguments.items()
                if ROGUE_ERRORS[args[0]]}
    # Each rogue causes its own error and no other (no overrun of a rogue that does not spin:
    # r_alloc, for one, never touches what it allocates).
    assert errors == expected, (f"errors per rogue: {errors}, expected {expected}"
                                + describe(runs["rogues"]))
    seen = set().union(*errors.values())
    assert SHOWN <= seen, SHOWN - seen


def test_flood_overflows_the_destination(runs):
    """r_flood sends as many messages as its source queue holds at every release from its
    AT-th on; the destination (a port nobody reads) fills with the first release's, then each
    later message is lost: one overflow event per message, at the end of the flooder's window.
    Nothing else overflows."""
    tables = read_tables(MODULE)
    events = runs["rogues"].events
    (start,) = [e for e in events if e["kind"] == "module_start"]
    maf = start["major_frame_ns"]
    overflows = [e for e in events if e["kind"] == "port" and e["event"] == "overflow"]
    want = []
    for name, args in tables.arguments.items():
        if args[0] != "flood":
            continue
        at = int(args[1])
        (channel,) = [c for c in read_channels(MODULE) if c.source[0] == name]
        ((dest, dport),) = channel.destinations
        depth = queue_depth(MODULE, *channel.source)
        assert queue_depth(MODULE, dest, dport) == depth  # filled by one release
        sends = [e for e in events if e["kind"] == "app_message" and e["src"] == name
                 and e["text"].startswith("flood: sent ")]
        # Released once per major frame, from frame 0: release AT is in frame AT - 1. Each
        # release tries 100 messages (rogue.c); the source queue takes `depth` of them.
        assert [e["t_ns"] // maf for e in sends] == list(range(at - 1, FRAMES)), sends[:3]
        assert {e["text"] for e in sends} == {f"flood: sent {depth}, refused {100 - depth}"}
        (window,) = [w for w in start["windows"] if w["partition"] == name]
        end = window["offset_ns"] + window["duration_ns"]
        for frame in range(at, FRAMES):
            want += [{"t_ns": frame * maf + end, "node": start["node"], "src": "ske",
                      "kind": "port", "event": "overflow", "channel": channel.name,
                      "partition": dest, "port": dport}] * depth
    assert want
    assert overflows == want, (f"{len(overflows)} overflow events, {len(want)} expected; "
                               f"first: {overflows[:1]}")
    assert not [e for e in runs["behaving"].events if e["kind"] == "port"
                and e["event"] == "overflow"]


def test_healthy_partitions_cannot_tell(runs):
    def healthy(run: Run) -> list[dict]:
        return [e for e in run.events
                if (e["kind"] == "window_start" and e["partition"] in HEALTHY)
                or (e["kind"] == "app_message" and e["src"] in HEALTHY)]

    got, want = healthy(runs["rogues"]), healthy(runs["behaving"])
    assert want and len([e for e in want if e["kind"] == "window_start"]) == 4 * FRAMES
    first = next((i for i, (a, b) in enumerate(zip(got, want, strict=False)) if a != b), None)
    assert got == want, (f"{len(got)} events, {len(want)} when the rogues behave; first "
                         f"difference at {first}: {got[first] if first is not None else None} "
                         f"instead of {want[first] if first is not None else None}"
                         + describe(runs["rogues"]))


def test_two_runs_write_identical_traces(runs):
    a, b = runs["rogues"].trace, runs["again"].trace
    assert a.count(b"\n") > FRAMES * 16
    if a != b:
        la, lb = a.splitlines(), b.splitlines()
        pairs = enumerate(zip(la, lb, strict=False))
        n = next((i for i, (x, y) in pairs if x != y), min(len(la), len(lb)))
        pytest.fail(f"the traces differ from line {n + 1} ({len(la)} and {len(lb)} lines):"
                    f"\n  {la[n][:200] if n < len(la) else b''!r}"
                    f"\n  {lb[n][:200] if n < len(lb) else b''!r}")
