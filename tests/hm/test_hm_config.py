# SPDX-License-Identifier: Apache-2.0
"""The HM tables as the loader takes them (docs/health-monitoring.md, "Writing the tables").

`ima-ske --check` refuses a module that breaks a rule with exit status 2 and one line on
standard error naming the file, the line and the element at fault and the rule broken; a
module without tables, or with tables that leave entries out, gets the documented defaults,
observed here in runs: every error at PARTITION level, Partition HM action IDLE for faults and
IGNORE for the timing errors DEADLINE_MISSED and WINDOW_OVERRUN, Module HM action IGNORE.
"""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass

import pytest

DIAG_RE = re.compile(r"^(?P<file>.+):(?P<line>\d+): error: (?P<element>\w+): (?P<message>.*) "
                     r"\(rule: (?P<rule>[^()]+)\)$")

SYS = "System_HM_Table"


def sys_table(*entries: str, state: int = 2) -> str:
    """A System_HM_Table with one System_State_Entry, each entry on its own line."""
    return "\n".join(["  <System_HM_Table>", f'    <System_State_Entry SystemState="{state}">',
                      *(f"      {e}" for e in entries), "    </System_State_Entry>",
                      "  </System_HM_Table>"])


def mod_table(*entries: str, state: int = 2) -> str:
    return sys_table(*entries, state=state).replace(SYS, "Module_HM_Table")


def part_table(*entries: str, state: int = 2, pid: int = 2, name: str = "faulty") -> str:
    return "\n".join([f'  <Partition_HM_Table PartitionIdentifier="{pid}" PartitionName="{name}">',
                      f'    <System_State_Entry SystemState="{state}">',
                      *(f"      {e}" for e in entries), "    </System_State_Entry>",
                      "  </Partition_HM_Table>"])


def level(error: int, lvl: str, extra: str = "") -> str:
    return f'<Error_ID_Level ErrorIdentifier="{error}" ErrorLevel="{lvl}"{extra}/>'


def action(error: int, act: str) -> str:
    return f'<Error_ID_Action ErrorIdentifier="{error}" Action="{act}"/>'


@dataclass(frozen=True)
class Bad:
    name: str
    tables: dict  # system / module / partition: XML text
    at: str  # the text of the element at fault (its line is found in the module)
    element: str
    rule: str | None  # the rule named, or None where any rule will do (the message says enough)
    says: tuple[str, ...]  # what the message names
    occurrence: int = 1  # which occurrence of `at` (the second of a duplicate)


BAD = [
    Bad("error identifier 11", {"system": sys_table(level(11, "PARTITION"))},
        'ErrorIdentifier="11"', "Error_ID_Level", None, ("ErrorIdentifier", "11")),
    Bad("error identifier 0", {"system": sys_table(level(0, "PARTITION"))},
        'ErrorIdentifier="0"', "Error_ID_Level", None, ("ErrorIdentifier", "0")),
    Bad("error identifier 11 in a Partition_HM_Table",
        {"partition": part_table(action(11, "IDLE"))},
        'ErrorIdentifier="11"', "Error_ID_Action", None, ("ErrorIdentifier", "11")),
    Bad("system state 4", {"system": sys_table(level(6, "PARTITION"), state=4)},
        'SystemState="4"', "System_State_Entry", None, ("SystemState", "4")),
    Bad("system state 4 in a Module_HM_Table", {"module": mod_table(action(6, "IGNORE"), state=4)},
        'SystemState="4"', "System_State_Entry", None, ("SystemState", "4")),
    Bad("duplicate level", {"system": sys_table(level(6, "PARTITION"), level(6, "MODULE"))},
        'ErrorIdentifier="6"', "Error_ID_Level", "one entry per error and system state",
        ("ErrorIdentifier=6", "MEMORY_VIOLATION", "SystemState 2"), occurrence=2),
    Bad("duplicate module action", {"module": mod_table(action(4, "IGNORE"), action(4, "RESET"))},
        'ErrorIdentifier="4"', "Error_ID_Action", "one entry per error and system state",
        ("ErrorIdentifier=4",), occurrence=2),
    # The same state twice in one table: still one entry per error and state.
    Bad("duplicate across two entries of one state",
        {"partition": part_table(action(3, "IDLE")).replace(
            "    </System_State_Entry>\n",
            '    </System_State_Entry>\n    <System_State_Entry SystemState="2">\n'
            f'      {action(3, "COLD_START")}\n    </System_State_Entry>\n')},
        'ErrorIdentifier="3"', "Error_ID_Action", "one entry per error and system state",
        ("ErrorIdentifier=3", "NUMERIC_ERROR"), occurrence=2),
    Bad("PROCESS level for WINDOW_OVERRUN", {"system": sys_table(level(9, "PROCESS"))},
        'ErrorIdentifier="9"', "Error_ID_Level", "process level needs a process that can go on",
        ("WINDOW_OVERRUN",)),
    Bad("PROCESS level for PARTITION_EXIT", {"system": sys_table(level(10, "PROCESS"))},
        'ErrorIdentifier="10"', "Error_ID_Level", "process level needs a process that can go on",
        ("PARTITION_EXIT",)),
    *[Bad(f"PROCESS level in state {st}", {"system": sys_table(level(6, "PROCESS"), state=st)},
          'ErrorIdentifier="6"', "Error_ID_Level", "process level needs a process that can go on",
          ("MEMORY_VIOLATION", name))
      for st, name in ((0, "MODULE_INIT"), (1, "PARTITION_INIT"), (3, "ERROR_HANDLER"))],
    *[Bad(f"module action {a}", {"module": mod_table(action(6, a))},
          f'Action="{a}"', "Error_ID_Action", None, (a,))
      for a in ("IDLE", "WARM_START", "COLD_START")],
    *[Bad(f"partition action {a}", {"partition": part_table(action(6, a))},
          f'Action="{a}"', "Error_ID_Action", None, (a,))
      for a in ("SHUTDOWN", "RESET")],
    Bad("ErrorCode of another error",
        {"system": sys_table(level(6, "PARTITION", ' ErrorCode="NUMERIC_ERROR"'))},
        'ErrorCode="NUMERIC_ERROR"', "Error_ID_Level", "ErrorCode agrees with ErrorIdentifier",
        ("MEMORY_VIOLATION", "NUMERIC_ERROR")),
    Bad("ErrorCode not an error code",
        {"system": sys_table(level(6, "PARTITION", ' ErrorCode="SEGFAULT"'))},
        'ErrorCode="SEGFAULT"', "Error_ID_Level", None, ("SEGFAULT",)),
    Bad("Partition_HM_Table of an unknown partition",
        {"partition": part_table(action(6, "IDLE"), pid=7, name="ghost")},
        "<Partition_HM_Table", "Partition_HM_Table", None, ("7", "ghost")),
    Bad("Partition_HM_Table naming two partitions",
        {"partition": part_table(action(6, "IDLE"), pid=2, name="healthy")},
        "<Partition_HM_Table", "Partition_HM_Table", None, ("faulty", "healthy")),
    Bad("two Partition_HM_Tables for one partition",
        {"partition": part_table(action(6, "IDLE")) + "\n" + part_table(action(3, "IDLE"))},
        "<Partition_HM_Table", "Partition_HM_Table", "one Partition_HM_Table per partition",
        ("faulty",), occurrence=2),
]


def line_of(text: str, needle: str, occurrence: int) -> int:
    lines = [n for n, line in enumerate(text.splitlines(), 1) if needle in line]
    assert len(lines) >= occurrence, f"{needle!r} occurs {len(lines)} times in the module"
    return lines[occurrence - 1]


def check(ske_binary, path, hm):
    return subprocess.run([str(ske_binary), "--check", str(path)], capture_output=True,
                          text=True, timeout=30, env=hm.ske_env())


@pytest.mark.parametrize("bad", BAD, ids=lambda b: b.name)
def test_loader_refuses(bad, ske_binary, tmp_path, hm):
    text = hm.hm_module("none 3", **bad.tables)
    path = hm.write_module(tmp_path, "bad", text)
    p = check(ske_binary, path, hm)
    assert p.returncode == 2, (p.returncode, p.stdout, p.stderr)
    assert p.stdout == ""
    lines = p.stderr.splitlines()
    assert len(lines) == 1, p.stderr
    m = DIAG_RE.match(lines[0])
    assert m, f"not 'file:line: error: element: message (rule: ...)': {lines[0]!r}"
    assert m["file"] == str(path), lines[0]
    assert int(m["line"]) == line_of(text, bad.at, bad.occurrence), lines[0]
    assert m["element"] == bad.element, lines[0]
    if bad.rule:
        assert m["rule"] == bad.rule, lines[0]
    for word in bad.says:
        assert word in m["message"], (word, lines[0])


GOOD = [
    ("every level and action", {
        "system": sys_table(level(1, "PROCESS"),
                            level(2, "PROCESS", ' ErrorCode="APPLICATION_ERROR"'),
                            level(3, "PARTITION"), level(4, "MODULE"), level(9, "PARTITION"),
                            level(10, "MODULE")),
        "module": mod_table(action(4, "IGNORE"), action(10, "RESET"), action(9, "SHUTDOWN")),
        "partition": part_table(action(3, "WARM_START"), action(1, "COLD_START"),
                                action(2, "IDLE"), action(9, "IGNORE"))}),
    # A window overrun never reaches an error handler (no PROCESS level for it), but its error
    # code, the hm event's error_code, is DEADLINE_MISSED.
    ("ErrorCode of a window overrun",
     {"system": sys_table(level(9, "PARTITION", ' ErrorCode="DEADLINE_MISSED"'))}),
    ("PARTITION and MODULE levels in every state", {
        "system": "\n".join(sys_table(level(6, "PARTITION"), level(9, "MODULE"), state=s)
                            for s in range(4))
                  .replace("  </System_HM_Table>\n  <System_HM_Table>\n", "")}),
]


@pytest.mark.parametrize("tables", [g[1] for g in GOOD], ids=[g[0] for g in GOOD])
def test_loader_accepts(tables, ske_binary, tmp_path, hm):
    path = hm.write_module(tmp_path, "good", hm.hm_module("none 3", **tables))
    p = check(ske_binary, path, hm)
    assert (p.returncode, p.stderr) == (0, ""), p.stderr


# ---- defaults, observed ----------------------------------------------------------------------

FRAMES = 8


@dataclass(frozen=True)
class Default:
    name: str
    faulty: str  # hm_rogue's Arguments
    tables: dict
    error: str
    level: str
    action: str
    final_state: str


DEFAULTS = [
    # No tables at all. An error handler does not make an error PROCESS level.
    Default("segv, no tables", "segv 3 handler", {}, "MEMORY_VIOLATION", "PARTITION", "IDLE",
            "idle"),
    Default("app_error, no tables", "app_error 3 handler", {}, "APPLICATION_ERROR", "PARTITION",
            "IDLE", "idle"),
    # Timing errors are IGNOREd: a host under load must not idle a healthy partition.
    Default("deadline, no tables", "deadline 3 handler", {}, "DEADLINE_MISSED", "PARTITION",
            "IGNORE", "running"),
    Default("exit, no tables", "exit 3", {}, "PARTITION_EXIT", "PARTITION", "IDLE", "idle"),
    Default("spin, no tables", "spin 3", {}, "WINDOW_OVERRUN", "PARTITION", "IGNORE", "stopped"),
    # Entries a table leaves out keep the default.
    Default("segv, System table without it", "segv 3 handler",
            {"system": sys_table(level(2, "PROCESS"), level(3, "MODULE"))},
            "MEMORY_VIOLATION", "PARTITION", "IDLE", "idle"),
    Default("segv, Partition table without it", "segv 3",
            {"partition": part_table(action(3, "COLD_START"), action(9, "IDLE"))},
            "MEMORY_VIOLATION", "PARTITION", "IDLE", "idle"),
    Default("deadline, Partition table without it", "deadline 3",
            {"partition": part_table(action(6, "COLD_START"), action(9, "IDLE"))},
            "DEADLINE_MISSED", "PARTITION", "IGNORE", "running"),
    Default("spin, Partition table without it", "spin 3",
            {"partition": part_table(action(6, "COLD_START"))},
            "WINDOW_OVERRUN", "PARTITION", "IGNORE", "stopped"),
    Default("segv at MODULE level, no Module table", "segv 3",
            {"system": sys_table(level(6, "MODULE"))}, "MEMORY_VIOLATION", "MODULE", "IGNORE",
            "running"),
]


@pytest.mark.parametrize("case", DEFAULTS, ids=lambda c: c.name)
def test_defaults(case, run_ske, tmp_path, hm):
    path = hm.write_module(tmp_path, "defaults", hm.hm_module(case.faulty, **case.tables))
    run = run_ske(path, frames=FRAMES, timeout=30)
    assert run.returncode == 0, hm.context(run)
    found = hm.hm_events(run.events)
    assert found, hm.context(run)
    for _, e in found:
        assert (e["error"], e["level"], e["action"], e["state"]) == \
            (case.error, case.level, case.action, "PROCESS"), e
        assert "note" not in e, e
    assert not [r for r in hm.reports(run.events, hm.FAULTY) if r.text.startswith("handler")]
    assert hm.stats_of(run, hm.FAULTY)["state"] == case.final_state, hm.context(run)
    if case.action == "IDLE":
        assert len(found) == 1
        (w,) = [w for w in hm.window_starts(run.events, hm.FAULTY) if w["frame"] == FRAMES - 1]
        assert w.get("partition_state") == "idle", w
    if case.error == "DEADLINE_MISSED":
        # Recorded and let go on: first at the deadline itself, 65 ms (released at 45 ms in
        # frame 2, TIME_CAPACITY one period); the late process goes on, nothing is restarted.
        assert found[0][1]["t_ns"] == 65_000_000, found[0][1]
        texts = [r.text for r in hm.reports(run.events, hm.FAULTY)]
        assert "after deadline rc=0" in texts, hm.context(run)
        assert not [m for m in run.of_kind("mode", partition=hm.FAULTY, src="ske")
                    if m.get("reason") != "power-on"], hm.context(run)
        assert all("partition_state" not in w for w in hm.window_starts(run.events, hm.FAULTY))
    if case.error == "WINDOW_OVERRUN":
        # Stopped at the end of each of its windows from the third on, and let go on.
        assert [e["frame"] for e in run.of_kind("overrun", partition=hm.FAULTY)] == \
            list(range(2, FRAMES))
        assert len(found) == FRAMES - 2
