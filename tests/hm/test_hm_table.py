# SPDX-License-Identifier: Apache-2.0
"""Health monitoring decided by the HM tables (ARINC 653 Part 1, 2.4; docs/health-monitoring.md),
table-driven: every error a partition can cause × the level the System HM table gives it ×
the action the Partition or Module HM table gives it, each case a module of its own run under
the real ima-ske.

Each module has a partition "faulty" running `hm_rogue FAULT 3 [handler]` (it misbehaves at
the third release of its process "rogue", in frame 2, while its process "beat" reports every
period) and a partition "healthy" running the same program well-behaved. A case checks:

- the decision: the `hm` event (error, level, action, partition, process, state, error code),
  and when it is taken: an error the partition reports is decided at once, at the partition's
  time when it happened (inside the window); one the SKE detects itself (an overrun, an exit)
  at the window's end;
- its effect on the faulty partition, seen in the trace, in what the partition reports and in
  the statistics;
- that nothing changes for the healthy partition: its windows and everything it reports are
  those of a run in which the faulty partition behaves (a module RESET restarts it too, by
  design: then its windows go on unchanged and it starts again with HM_MODULE_RESTART).

The tables of a case also hold decoys, entries that must not be used: a Partition HM action
for an error decided at process or module level, a Module HM action (SHUTDOWN) for an error
decided at partition level.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import pytest

FRAMES = 10
AT = 3  # the release of process "rogue" at which it misbehaves (release 1 is in frame 0)

# What becomes of the process that caused the error.
DORMANT = "dormant"  # a fault signal: it cannot resume at the faulting instruction
GOES_ON = "goes on"  # the call that caused the error returns (RAISE_APPLICATION_ERROR, a wait)
OVERRUN = "overrun"  # it keeps the CPU: the SKE stops the partition at its window's end
EXIT = "exit"  # the partition's process ends


@dataclass(frozen=True)
class Fault:
    arg: str  # hm_rogue's FAULT
    error: str  # `error` of the hm event
    outcome: str
    apex_code: int  # ERROR_CODE_TYPE as GET_ERROR_STATUS gives it; the hm event's error_code
    frame: int = AT - 1  # the frame whose faulty window decides the error


FAULTS = [
    #     FAULT         error                outcome  ERROR_CODE
    Fault("segv",       "MEMORY_VIOLATION",  DORMANT, 5),
    Fault("write_port", "MEMORY_VIOLATION",  DORMANT, 5),  # its read-only destination port
    Fault("divide",     "NUMERIC_ERROR",     DORMANT, 2),
    Fault("stack",      "STACK_OVERFLOW",    DORMANT, 4),
    Fault("apex",       "ILLEGAL_REQUEST",   DORMANT, 3),  # an invalid address to an APEX call
    Fault("app_error",  "APPLICATION_ERROR", GOES_ON, 1),
    # Released in frame 2 (45 ms), deadline one period later (TIME_CAPACITY = PERIOD), 65 ms:
    # the start of its window of frame 3, the first scheduling point where now >= deadline.
    Fault("deadline",   "DEADLINE_MISSED",   GOES_ON, 0, frame=AT),
    Fault("spin",       "WINDOW_OVERRUN",    OVERRUN, 0),
    Fault("exit",       "PARTITION_EXIT",    EXIT,    6),
]

ERROR_IDS = {"DEADLINE_MISSED": 1, "APPLICATION_ERROR": 2, "NUMERIC_ERROR": 3,
             "ILLEGAL_REQUEST": 4, "STACK_OVERFLOW": 5, "MEMORY_VIOLATION": 6,
             "WINDOW_OVERRUN": 9, "PARTITION_EXIT": 10}
PROCESS_STATE = 2  # SystemState: an ARINC process runs

# The configured level, whether the faulty partition has an error handler, the configured
# action; then the decision the trace must show.
DECISIONS = [
    # level       handler  action           -> level        action
    ("PROCESS",   True,    "ERROR_HANDLER",    "PROCESS",   "ERROR_HANDLER"),
    ("PROCESS",   False,   "IGNORE",           "PARTITION", "IGNORE"),  # no handler: escalated
    ("PROCESS",   False,   "IDLE",             "PARTITION", "IDLE"),
    ("PROCESS",   False,   "WARM_START",       "PARTITION", "WARM_START"),
    ("PROCESS",   False,   "COLD_START",       "PARTITION", "COLD_START"),
    ("PARTITION", True,    "IGNORE",           "PARTITION", "IGNORE"),  # the handler stays out
    ("PARTITION", True,    "IDLE",             "PARTITION", "IDLE"),
    ("PARTITION", True,    "WARM_START",       "PARTITION", "WARM_START"),
    ("PARTITION", True,    "COLD_START",       "PARTITION", "COLD_START"),
    ("MODULE",    True,    "IGNORE",           "MODULE",    "IGNORE"),
    ("MODULE",    True,    "SHUTDOWN",         "MODULE",    "SHUTDOWN"),
    ("MODULE",    True,    "RESET",            "MODULE",    "RESET"),
]


@dataclass(frozen=True)
class Case:
    fault: Fault
    level: str
    handler: bool
    action: str
    decided_level: str
    decided_action: str

    def __str__(self) -> str:
        return f"{self.fault.arg}-{self.level}{'+handler' if self.handler else ''}-{self.action}"

    @property
    def escalated(self) -> bool:
        return self.level == "PROCESS" and not self.handler

    def tables(self) -> dict:
        """The three tables of the case, with decoys where the decision must not look."""
        e = ERROR_IDS[self.fault.error]
        partition_action = self.action if self.decided_level == "PARTITION" else "COLD_START"
        module_action = self.action if self.level == "MODULE" else "SHUTDOWN"
        return {"system": {PROCESS_STATE: {e: self.level}},
                "module": {PROCESS_STATE: {e: module_action}},
                "partition": {PROCESS_STATE: {e: partition_action}}}


# PROCESS level is refused by the loader for window overruns and partition exits (no process
# whose error handler could act): those two errors have no PROCESS rows.
CASES = [Case(f, *d) for f in FAULTS for d in DECISIONS
         if not (d[0] == "PROCESS" and f.outcome in (OVERRUN, EXIT))]


# ---- running a case ----------------------------------------------------------------------

_reference: dict[str, object] = {}


@pytest.fixture
def reference(run_ske, tmp_path, hm):
    """The run in which the faulty partition behaves (shared by all the cases)."""
    if "run" not in _reference:
        path = hm.write_module(tmp_path, "reference", hm.hm_module(f"none {AT}"))
        run = run_ske(path, frames=FRAMES, timeout=30)
        assert run.returncode == 0, run.stderr
        assert not run.of_kind("hm")
        _reference["run"] = run
    return _reference["run"]


@dataclass
class Observed:
    """A case's run and what the checks need of it."""

    run: object
    case: Case
    hm_at: int  # trace index of the first hm event about the faulty partition
    first: dict  # that event
    rogue_id: int  # process identifier of process "rogue" (from the trace's process events)

    @property
    def events(self) -> list[dict]:
        return self.run.events

    def faulty_after(self, hm) -> list:
        return [r for r in hm.reports(self.events, hm.FAULTY) if r.index > self.hm_at]

    def ske_modes(self, hm, partition: str) -> list[tuple[int, dict]]:
        """The mode changes the SKE made, after power-on."""
        return [(i, e) for i, e in enumerate(self.events) if e["kind"] == "mode"
                and e["src"] == "ske" and e["partition"] == partition
                and e.get("reason") != "power-on"]


def observe(run, case: Case, hm) -> Observed:
    ctx = hm.context(run)
    assert run.stats is not None, "no statistics" + ctx
    found = hm.hm_events(run.events)
    assert found, f"no hm event about {hm.FAULTY}" + ctx
    (rogue_id,) = {e["process"] for e in run.events if e["kind"] == "process"
                   and e["src"] == hm.FAULTY and e["name"] == "rogue"}
    at, first = found[0]
    return Observed(run, case, at, first, rogue_id)


# ---- the decision ------------------------------------------------------------------------

def check_decision(o: Observed, hm) -> None:
    c, f, e = o.case, o.case.fault, o.first
    ctx = hm.context(o.run)
    assert (e["error"], e["level"], e["action"]) == \
        (f.error, c.decided_level, c.decided_action), ctx
    assert e["partition"] == hm.FAULTY and e["state"] == "PROCESS", e
    assert e["error_code"] == f.apex_code, e
    # Errors the partition detects name the failed process; the SKE's own (an overrun, an
    # exit) name none.
    if f.outcome in (OVERRUN, EXIT):
        assert (e["process"], e["process_id"]) == (None, 0), e
    else:
        assert (e["process"], e["process_id"]) == ("rogue", o.rogue_id), e
    # Decided in the partition (its error handler) or by the SKE.
    assert e["src"] == (hm.FAULTY if c.decided_level == "PROCESS" else "ske"), e
    if c.escalated:
        assert "escalated" in e.get("note", ""), e
    else:
        assert "note" not in e, e
    # Inside the faulty window of the frame the error happens in, at the exact time.
    (start,) = [i for i, x in enumerate(o.events) if x["kind"] == "window_start"
                and x["partition"] == hm.FAULTY and x["frame"] == f.frame]
    end = next(i for i, x in enumerate(o.events) if i > start and x["kind"] == "window_end")
    assert start < o.hm_at < end, ctx
    t_window = f.frame * hm.MAF_NS + hm.FAULTY_OFFSET_NS
    if f.outcome in (OVERRUN, EXIT):
        # Detected by the SKE: decided at the window's end.
        assert e["t_ns"] == t_window + hm.FAULTY_DURATION_NS, e
    elif f.arg == "deadline":
        # At the deadline itself, release + TIME_CAPACITY (one period, the major frame): the
        # start of this window, the first scheduling point where now >= deadline.
        release = (f.frame - 1) * hm.MAF_NS + hm.FAULTY_OFFSET_NS
        assert e["t_ns"] == release + hm.MAF_NS == t_window, e
        assert e["message"] == f"deadline {e['t_ns']} ns passed at {e['t_ns']} ns", e
    else:
        # Reported by the partition and decided at once, at its time when it misbehaved
        # (emulated time does not pass while it computes: its window's start), right after
        # what it reported before the error.
        (misbehave,) = [r for r in hm.reports(o.events, hm.FAULTY)
                        if r.text == f"misbehave {f.arg}" and r.index < o.hm_at]
        assert e["t_ns"] == misbehave.t_ns == t_window, (e, misbehave)
        before = [r for r in hm.reports(o.events, hm.FAULTY) if r.index < o.hm_at]
        assert before[-1].text.startswith(("misbehave ", "write_port ")), before[-1]
    assert o.run.stats["hm_events"] == len(o.run.of_kind("hm"))
    if f.arg == "write_port":
        # The address that faulted is the one the partition wrote to: the read-only mapping
        # of one of its destination ports.
        (target,) = [r.text.split() for r in hm.reports(o.events, hm.FAULTY)
                     if r.text.startswith("write_port ")][:1]
        assert target[2] in (f"memfd:ima-{hm.FAULTY}-ROGUE_IN",
                             f"memfd:ima-{hm.FAULTY}-ROGUE_Q_IN"), target
        assert e["message"] == f"SIGSEGV at address {target[1]}", e
    # The trace is in time order, module_stop included (after a SHUTDOWN: the window's end).
    times = [x["t_ns"] for x in o.events]
    assert times == sorted(times)


# ---- the effects -------------------------------------------------------------------------

HANDLER_RE = re.compile(r"^handler code=(\d+) failed=(\d+) state=(\w+): (.*)$")


def last_frame_reports(o: Observed, hm, prefix: str) -> list:
    t0 = (FRAMES - 1) * hm.MAF_NS
    return [r for r in hm.reports(o.events, hm.FAULTY)
            if r.t_ns >= t0 and r.text.startswith(prefix)]


def assert_not_restarted(o: Observed, hm) -> None:
    assert not o.ske_modes(hm, hm.FAULTY), hm.context(o.run)
    assert not [r for r in o.faulty_after(hm) if r.text.startswith("start ")], hm.context(o.run)
    assert hm.stats_of(o.run, hm.FAULTY)["restarts"] == 0


def assert_windows_alive(o: Observed, hm) -> None:
    starts = hm.window_starts(o.events, hm.FAULTY)
    assert len(starts) == FRAMES
    assert all("partition_state" not in w for w in starts), starts


def effect_error_handler(o: Observed, hm) -> None:
    """The handler reads the error (GET_ERROR_STATUS) at once; a faulted process is DORMANT
    and the handler STARTs it again; one whose call returns goes on after the handler."""
    ctx = hm.context(o.run)
    f = o.case.fault
    after = o.faulty_after(hm)
    handled = [r for r in after if HANDLER_RE.match(r.text)]
    assert handled, "the error handler reported nothing" + ctx
    code, failed, state, _ = HANDLER_RE.match(handled[0].text).groups()
    assert (int(code), int(failed)) == (f.apex_code, o.rogue_id), handled[0]
    assert handled[0].t_ns == o.first["t_ns"], handled[0]
    later = [r for r in after if r.index > handled[0].index]
    # The handler runs first, then the partition goes on in the same window.
    assert any(r.text.startswith("beat ") and r.t_ns == handled[0].t_ns for r in later), ctx
    if f.outcome == DORMANT:
        assert state == "DORMANT", handled[0]
        assert later and later[0].text == f"handler START({o.rogue_id}) rc=0", ctx
        restarted = [i for i, e in enumerate(o.events) if i > handled[0].index
                     and e["kind"] == "process" and e["src"] == hm.FAULTY
                     and e["name"] == "rogue" and e["event"] == "start"]
        assert restarted, "no process start after the handler" + ctx
        # The process starts from its entry point: its count starts again.
        assert any(r.process == o.rogue_id and r.text == "tick 1" for r in later), ctx
    else:
        assert state != "DORMANT", handled[0]
        assert any(r.process == o.rogue_id and r.text == f"after {f.arg} rc=0" for r in later), ctx
    assert all(e["level"] == "PROCESS" and e["action"] == "ERROR_HANDLER"
               for _, e in hm.hm_events(o.events)), ctx
    assert_not_restarted(o, hm)
    assert_windows_alive(o, hm)
    assert hm.stats_of(o.run, hm.FAULTY)["state"] == "running"


def effect_ignore(o: Observed, hm) -> None:
    """Recorded, the partition goes on: a faulted process stays DORMANT while the others go
    on; after an overrun the partition is stopped until its next window; after an exit it
    stays down."""
    ctx = hm.context(o.run)
    f = o.case.fault
    after = o.faulty_after(hm)
    assert not [r for r in after if r.text.startswith("handler")], "the handler ran" + ctx
    assert_not_restarted(o, hm)
    faulty = hm.stats_of(o.run, hm.FAULTY)
    if f.outcome in (DORMANT, GOES_ON):
        # Decided at once: the partition is granted the rest of the same window and goes on
        # in it (its process beat runs its release of this frame, at the error's time).
        assert after and after[0].t_ns == o.first["t_ns"], ctx
        assert any(r.text.startswith("beat ") and r.t_ns == o.first["t_ns"] for r in after), ctx
        end = next(x for x in o.events[o.hm_at:] if x["kind"] == "window_end"
                   and x["partition"] == hm.FAULTY)
        assert end["yielded"] is True and end["yield_t_ns"] == o.first["t_ns"], end
    if f.outcome == DORMANT:
        assert len(hm.hm_events(o.events)) == 1, ctx
        assert not [r for r in after if r.process == o.rogue_id], ctx
        beats = [r for r in after if r.text.startswith("beat ")]
        assert beats and all(r.text.endswith("rogue=DORMANT") for r in beats), ctx
        assert last_frame_reports(o, hm, "beat "), "the partition stopped reporting" + ctx
        assert_windows_alive(o, hm)
        assert faulty["state"] == "running"
    elif f.outcome == GOES_ON:
        assert any(r.process == o.rogue_id and r.text == f"after {f.arg} rc=0" for r in after), ctx
        assert last_frame_reports(o, hm, "tick "), "process rogue stopped" + ctx
        assert last_frame_reports(o, hm, "beat "), "process beat stopped reporting" + ctx
        assert_windows_alive(o, hm)
        assert faulty["state"] == "running"
    elif f.outcome == OVERRUN:
        # Stopped at the end of every window from then on, each time an error IGNOREd; the
        # spinning process keeps the CPU, nothing else in the partition runs.
        frames = list(range(f.frame, FRAMES))
        overruns = o.run.of_kind("overrun", partition=hm.FAULTY)
        assert [e["frame"] for e in overruns] == frames, ctx
        assert all(e["action"] == "stopped" for e in overruns)
        errors = hm.hm_events(o.events)
        assert [(e["error"], e["action"]) for _, e in errors] == \
            [("WINDOW_OVERRUN", "IGNORE")] * len(frames)
        ends = o.run.of_kind("window_end", partition=hm.FAULTY)
        assert [e["yielded"] for e in ends] == [True] * f.frame + [False] * len(frames)
        assert not after, ctx
        assert_windows_alive(o, hm)
        assert faulty["state"] == "stopped" and faulty["overruns"] == len(frames)
    else:  # EXIT
        (ex,) = o.run.of_kind("partition_exit", partition=hm.FAULTY)
        assert (ex["status"], ex["code"]) == ("exited", 7), ex
        assert o.events.index(ex) < o.hm_at
        later = [w for w in hm.window_starts(o.events, hm.FAULTY) if w["frame"] > f.frame]
        assert later and all(w.get("partition_state") == "exited" for w in later), later
        assert not after, ctx
        assert (faulty["state"], faulty["exit_status"]) == ("exited", 7)


def effect_idle(o: Observed, hm) -> None:
    """The partition's process is ended; its windows stay in the plan, empty."""
    ctx = hm.context(o.run)
    f = o.case.fault
    mode = o.events[o.hm_at + 1]
    assert (mode["kind"], mode["src"], mode["partition"], mode["mode"], mode.get("reason")) == \
        ("mode", "ske", hm.FAULTY, "IDLE", "health monitor"), ctx
    assert mode["t_ns"] == o.first["t_ns"]
    later = [w for w in hm.window_starts(o.events, hm.FAULTY) if w["frame"] > f.frame]
    assert len(later) == FRAMES - 1 - f.frame
    assert all(w.get("partition_state") == "idle" for w in later), later
    assert not [e for e in o.events[o.hm_at:] if e["src"] == hm.FAULTY], "it still ran" + ctx
    assert len(hm.hm_events(o.events)) == 1, ctx
    faulty = hm.stats_of(o.run, hm.FAULTY)
    assert (faulty["state"], faulty["restarts"]) == ("idle", 0)


def effect_restart(o: Observed, hm) -> None:
    """A new process of the partition, started at once: its initialisation runs in its next
    window (not in the rest of the window where the restart was decided), in the mode the
    action names, with start condition HM_PARTITION_RESTART (3)."""
    ctx = hm.context(o.run)
    f = o.case.fault
    action = o.case.decided_action
    mode = o.events[o.hm_at + 1]
    assert (mode["kind"], mode["src"], mode["partition"], mode["mode"], mode.get("reason")) == \
        ("mode", "ske", hm.FAULTY, action, "health monitor"), ctx
    assert mode["t_ns"] == o.first["t_ns"]
    # Decided mid-window or at its end, the new process starts at the next window.
    after = o.faulty_after(hm)
    assert after and after[0].text == f"start condition=3 mode={action}", ctx
    assert after[0].t_ns == (f.frame + 1) * hm.MAF_NS + hm.FAULTY_OFFSET_NS, after[0]
    assert any(r.text == "tick 1" for r in after), ctx
    assert not [r for r in after if r.text.startswith("handler")], "the handler ran" + ctx
    # It misbehaves again in each new life: one restart per error.
    errors = hm.hm_events(o.events)
    assert all(e["action"] == action for _, e in errors), ctx
    faulty = hm.stats_of(o.run, hm.FAULTY)
    assert faulty["restarts"] == len(errors) == len(o.ske_modes(hm, hm.FAULTY)), ctx
    starts = hm.window_starts(o.events, hm.FAULTY)
    assert all("partition_state" not in w for w in starts), starts
    assert faulty["state"] in ("running", "stopped")


def effect_shutdown(o: Observed, hm) -> None:
    """The run ends at once: exit status 3, module_stop with reason hm_shutdown, timed at the
    end of the window where the shutdown was decided."""
    ctx = hm.context(o.run)
    f = o.case.fault
    assert o.run.returncode == 3, ctx
    rest = o.events[o.hm_at + 1:]
    assert [e["kind"] for e in rest] == ["window_end", "module_stop"], rest
    assert (rest[0]["partition"], rest[0]["frame"]) == (hm.FAULTY, f.frame)
    assert (rest[1]["reason"], rest[1]["frames"]) == ("hm_shutdown", f.frame), rest[1]
    window_end = f.frame * hm.MAF_NS + hm.FAULTY_OFFSET_NS + hm.FAULTY_DURATION_NS
    assert rest[0]["t_ns"] == rest[1]["t_ns"] == window_end, rest
    assert o.run.stats["exit_reason"] == "hm_shutdown"


def effect_reset(o: Observed, hm) -> None:
    """At the next major frame every partition's process is ended and started again, with
    start condition HM_MODULE_RESTART (2); module time goes on."""
    ctx = hm.context(o.run)
    f = o.case.fault
    assert o.run.returncode == 0, ctx
    t_reset = (f.frame + 1) * hm.MAF_NS
    for name in (hm.HEALTHY, hm.FAULTY):
        resets = o.ske_modes(hm, name)
        assert resets, f"{name} was not reset" + ctx
        i, first = resets[0]
        assert (first["t_ns"], first["mode"], first["reason"]) == \
            (t_reset, "COLD_START", "module reset"), first
        assert i > o.hm_at
        assert all(e["reason"] == "module reset" for _, e in resets)
        mine = [r for r in hm.reports(o.events, name) if r.index > i]
        assert mine and mine[0].text == "start condition=2 mode=COLD_START", ctx
        assert hm.stats_of(o.run, name)["restarts"] == len(resets)
    # Module time goes on: every window of every frame, at its time.
    starts = o.run.of_kind("window_start")
    offsets = {1: 0, hm.FAULTY_WINDOW: hm.FAULTY_OFFSET_NS, 3: 10_000_000}
    assert [(w["frame"], w["window"], w["t_ns"]) for w in starts] == [
        (fr, w, fr * hm.MAF_NS + offsets[w]) for fr in range(FRAMES) for w in (1, 2, 3)]
    assert all("partition_state" not in w for w in starts)
    assert o.run.of_kind("module_stop")[0]["frames"] == FRAMES


EFFECTS = {
    "ERROR_HANDLER": effect_error_handler,
    "IGNORE": effect_ignore,
    "IDLE": effect_idle,
    "WARM_START": effect_restart,
    "COLD_START": effect_restart,
    "SHUTDOWN": effect_shutdown,
    "RESET": effect_reset,
}


# ---- the healthy partition ---------------------------------------------------------------

def check_healthy_unaffected(o: Observed, reference, hm) -> None:
    mine = hm.about(o.events, hm.HEALTHY)
    ref = hm.about(reference.events, hm.HEALTHY)
    action = o.case.decided_action
    if action == "SHUTDOWN":
        assert mine == [e for e in ref if e["t_ns"] < o.first["t_ns"]]
    elif action == "RESET":
        t_reset = (o.case.fault.frame + 1) * hm.MAF_NS
        assert [e for e in mine if e["t_ns"] < t_reset] == [e for e in ref if e["t_ns"] < t_reset]
        assert hm.window_starts(mine, hm.HEALTHY) == hm.window_starts(ref, hm.HEALTHY)
    else:
        assert mine == ref
        assert len(hm.window_starts(mine, hm.HEALTHY)) == 2 * FRAMES


@pytest.mark.parametrize("case", CASES, ids=str)
def test_hm_decision_and_effect(case, run_ske, tmp_path, hm, reference):
    faulty = f"{case.fault.arg} {AT}" + (" handler" if case.handler else "")
    path = hm.write_module(tmp_path, str(case), hm.hm_module(
        faulty, **case.tables(), system_partition=case.fault.arg == "write_port"))
    run = run_ske(path, frames=FRAMES, timeout=30)
    assert run.returncode == (3 if case.decided_action == "SHUTDOWN" else 0), hm.context(run)
    o = observe(run, case, hm)
    check_decision(o, hm)
    EFFECTS[case.decided_action](o, hm)
    check_healthy_unaffected(o, reference, hm)
    assert not run.of_kind("start_failed")
    assert not run.of_kind("events_dropped")


# ---- errors during the partition's initialisation ------------------------------------------

PARTITION_INIT = 1  # SystemState


@dataclass(frozen=True)
class InitCase:
    """hm_rogue FAULT 0: the fault happens in the initialisation process, before NORMAL mode."""

    name: str
    fault: str
    error: str
    tables: dict
    level: str  # decided
    action: str  # decided
    note: str  # a word of the hm event's note; "" for no note
    final_state: str  # the faulty partition's state at the end of the run
    hm_note: str = ""  # a word of the hm_note event right after the hm event; "" for none


INIT_CASES = [
    # A fault during initialisation cannot be IGNOREd: nothing could run. The partition is
    # idled, and the hm event says so.
    InitCase("segv-PARTITION-IGNORE", "segv", "MEMORY_VIOLATION",
             {"partition": {PARTITION_INIT: {6: "IGNORE"}}}, "PARTITION", "IDLE", "idled", "idle"),
    # Module level IGNORE: the failed initialisation cannot go on either. The hm event keeps
    # the module's decision; an hm_note right after it says why the partition is idled.
    InitCase("segv-MODULE-IGNORE", "segv", "MEMORY_VIOLATION",
             {"system": {PARTITION_INIT: {6: "MODULE"}}, "module": {PARTITION_INIT: {6: "IGNORE"}}},
             "MODULE", "IGNORE", "", "idle", hm_note="idled"),
    # An application error returns: the initialisation goes on, NORMAL mode follows.
    InitCase("app_error-PARTITION-IGNORE", "app_error", "APPLICATION_ERROR",
             {"partition": {PARTITION_INIT: {2: "IGNORE"}}}, "PARTITION", "IGNORE", "",
             "running"),
    InitCase("segv-PARTITION-COLD_START", "segv", "MEMORY_VIOLATION",
             {"partition": {PARTITION_INIT: {6: "COLD_START"}}}, "PARTITION", "COLD_START", "",
             "running"),
    InitCase("exit-PARTITION-WARM_START", "exit", "PARTITION_EXIT",
             {"partition": {PARTITION_INIT: {10: "WARM_START"}}}, "PARTITION", "WARM_START", "",
             "running"),
    # The tables are per system state: entries for state PROCESS do not apply during
    # initialisation, which keeps the defaults (PARTITION level, IDLE).
    InitCase("segv-tables-for-PROCESS-only", "segv", "MEMORY_VIOLATION",
             {"system": {PROCESS_STATE: {6: "MODULE"}}, "module": {PROCESS_STATE: {6: "SHUTDOWN"}},
              "partition": {PROCESS_STATE: {6: "COLD_START"}}}, "PARTITION", "IDLE", "", "idle"),
]


@pytest.mark.parametrize("case", INIT_CASES, ids=lambda c: c.name)
def test_hm_during_partition_initialisation(case, run_ske, tmp_path, hm, reference):
    path = hm.write_module(tmp_path, case.name, hm.hm_module(f"{case.fault} 0", **case.tables))
    run = run_ske(path, frames=FRAMES, timeout=30)
    ctx = hm.context(run)
    assert run.returncode == 0, ctx
    found = hm.hm_events(run.events)
    assert found, ctx
    at, e = found[0]
    assert (e["error"], e["level"], e["action"], e["state"]) == \
        (case.error, case.level, case.action, "PARTITION_INIT"), e
    assert (e["src"], e["partition"], e["process"], e["process_id"]) == \
        ("ske", hm.FAULTY, None, 0), e
    # An error the partition reports is decided at once, at its time when it happened (its
    # first window's start); its process's end, which the SKE detects, at the window's end.
    decided_at = hm.FAULTY_OFFSET_NS
    if case.error == "PARTITION_EXIT":
        decided_at += hm.FAULTY_DURATION_NS
    assert e["t_ns"] == decided_at, e
    if case.note:
        assert case.note in e.get("note", ""), e
    else:
        assert "note" not in e, e
    notes = run.of_kind("hm_note")
    if case.hm_note:
        assert run.events[at + 1] == notes[0], ctx
        assert (notes[0]["src"], notes[0]["partition"], notes[0]["t_ns"]) == \
            ("ske", hm.FAULTY, e["t_ns"]), notes[0]
        assert case.hm_note in notes[0]["note"], notes[0]
        assert len(notes) == 1, notes
    else:
        assert not notes, notes
    faulty = hm.stats_of(run, hm.FAULTY)
    assert faulty["state"] == case.final_state, ctx
    after = [r for r in hm.reports(run.events, hm.FAULTY) if r.index > at]
    if case.final_state == "idle":
        (mode,) = [m for m in run.of_kind("mode", partition=hm.FAULTY) if m["src"] == "ske"
                   and m.get("reason") != "power-on"]
        assert (mode["t_ns"], mode["mode"], mode["from"], mode["reason"]) == \
            (e["t_ns"], "IDLE", "COLD_START", "health monitor")
        assert run.events.index(mode) == at + 1 + len(notes), ctx
        assert not after, ctx
    elif case.action == "IGNORE":
        # The initialisation goes on in the rest of the same window, into NORMAL mode.
        assert after and after[0].text == "after app_error rc=0", ctx
        normal = run.of_kind("mode", partition=hm.FAULTY, src=hm.FAULTY, mode="NORMAL")
        assert normal and run.events.index(normal[0]) > at, ctx
        assert normal[0]["t_ns"] == e["t_ns"], normal[0]
        assert any(r.text == "tick 1" and r.t_ns == e["t_ns"] for r in after), ctx
    else:
        # Restarted, failing again in each new initialisation: one restart per error. The new
        # process starts in the next window.
        assert after and after[0].text == f"start condition=3 mode={case.action}", ctx
        assert after[0].t_ns == hm.MAF_NS + hm.FAULTY_OFFSET_NS, after[0]
        assert len(found) >= 2 and faulty["restarts"] == len(found), ctx
    assert hm.about(run.events, hm.HEALTHY) == hm.about(reference.events, hm.HEALTHY)


# ---- an IGNOREd error costs the partition nothing -------------------------------------------

@pytest.mark.parametrize("fault,level", [("segv", "PARTITION"), ("app_error", "PARTITION"),
                                         ("segv", "MODULE")])
def test_ignored_error_leaves_the_partition_its_window(fault, level, run_ske, tmp_path, hm,
                                                       reference):
    """IGNORE: the partition goes on (docs/health-monitoring.md) - in the window where the
    error happened, not only from its next window on. Its other process, "beat", runs its
    release of that frame in that frame, at the same time as when nothing goes wrong: a
    partition that ignores an error loses nothing of its window, nor its processes their
    deadlines."""
    e = ERROR_IDS[{"segv": "MEMORY_VIOLATION", "app_error": "APPLICATION_ERROR"}[fault]]
    tables = {"system": {PROCESS_STATE: {e: level}},
              "module" if level == "MODULE" else "partition": {PROCESS_STATE: {e: "IGNORE"}}}
    path = hm.write_module(tmp_path, f"{fault}-{level}", hm.hm_module(f"{fault} {AT}", **tables))
    run = run_ske(path, frames=FRAMES, timeout=30)
    assert run.returncode == 0, hm.context(run)
    ((_, first),) = hm.hm_events(run.events)
    assert first["action"] == "IGNORE", first

    def beats(events):
        return [(r.t_ns, r.text.split()[1]) for r in hm.reports(events, hm.FAULTY)
                if r.text.startswith("beat ")]

    got, want = beats(run.events), beats(reference.events)
    late = [(w, g) for w, g in zip(want, got, strict=False) if w != g]
    assert got == want, (f"{hm.FAULTY}'s process beat ran late after the IGNOREd error "
                         f"(expected (t_ns, release), got): {late[:3]}" + hm.context(run))


# ---- a fault in the error handler ------------------------------------------------------------

ERROR_HANDLER_STATE = 3  # SystemState: the partition's error handler runs


@pytest.mark.parametrize("action", ["IGNORE", "IDLE", "COLD_START"])
def test_fault_in_the_error_handler(action, run_ske, tmp_path, hm, reference):
    """The error handler itself faults while handling a MEMORY_VIOLATION of process rogue: an
    error in state ERROR_HANDLER, which the loader keeps from PROCESS level, so the Partition HM
    table's entry for that state decides (the entry for state PROCESS is a decoy)."""
    tables = {"system": {PROCESS_STATE: {6: "PROCESS"}},
              "partition": {PROCESS_STATE: {6: "WARM_START"}, ERROR_HANDLER_STATE: {6: action}}}
    path = hm.write_module(tmp_path, f"eh-{action}",
                           hm.hm_module(f"segv {AT} faulty_handler", **tables))
    run = run_ske(path, frames=FRAMES, timeout=30)
    ctx = hm.context(run)
    assert run.returncode == 0, ctx
    found = hm.hm_events(run.events)
    assert len(found) >= 2, ctx
    (_, first), (at, second) = found[:2]
    assert (first["level"], first["action"], first["state"]) == \
        ("PROCESS", "ERROR_HANDLER", "PROCESS")
    assert (second["error"], second["level"], second["action"], second["state"], second["src"]) == \
        ("MEMORY_VIOLATION", "PARTITION", action, "ERROR_HANDLER", "ske"), second
    # The failed process is the error handler itself (identifier 0), decided at once.
    assert (second["process"], second["process_id"]) == ("ERROR_HANDLER", 0), second
    assert second["t_ns"] == first["t_ns"] == (AT - 1) * hm.MAF_NS + hm.FAULTY_OFFSET_NS, second
    handler = [r for r in hm.reports(run.events, hm.FAULTY) if r.text == "handler misbehaves"]
    assert handler and handler[0].index < at, ctx
    faulty = hm.stats_of(run, hm.FAULTY)
    after = [r for r in hm.reports(run.events, hm.FAULTY) if r.index > at]
    if action == "IGNORE":
        # The partition goes on in the rest of the window: process rogue, which the handler
        # STARTed again, runs from its entry point, and beat its release of this frame. The
        # handler, DORMANT again, takes the next error.
        now = [r.text for r in after if r.t_ns == second["t_ns"]]
        assert "tick 1" in now and f"beat {AT} rogue=WAITING" in now, ctx
        assert faulty["state"] == "running" and faulty["restarts"] == 0
        assert len(found) >= 3 and found[2][1]["action"] == "ERROR_HANDLER", ctx
        assert any(r.text.startswith("handler code=5 ") for r in after), ctx
    elif action == "IDLE":
        assert faulty["state"] == "idle" and len(found) == 2 and not after, ctx
    else:
        assert after and after[0].text == "start condition=3 mode=COLD_START", ctx
        assert after[0].t_ns == AT * hm.MAF_NS + hm.FAULTY_OFFSET_NS, after[0]  # next window
        assert faulty["restarts"] >= 1
    assert hm.about(run.events, hm.HEALTHY) == hm.about(reference.events, hm.HEALTHY)


# ---- the example's rogue program ---------------------------------------------------------------

ROGUE_START_RE = re.compile(
    r"^start: (\w+) at release (\d+)(, with error handler)?, start condition (\d)$")
ROGUE_HANDLER_RE = re.compile(r"^handler: error (\d+) in process (\d+): ")


# rogue.c has no exit; a window overrun cannot be configured at PROCESS level.
ROGUE_CASES = [pytest.param(f, d, id=f"{f.arg}-{d}") for f in FAULTS if f.outcome != EXIT
               for d in ("PROCESS+handler", "PARTITION-COLD_START")
               if not (f.outcome == OVERRUN and d == "PROCESS+handler")]


@pytest.mark.parametrize("fault,decision", ROGUE_CASES)
def test_rogue_program_is_decided_alike(fault, decision, run_ske, tmp_path, hm, reference):
    """partitions/rogues/rogue.c, the example's rogue program, in the faulty partition's place:
    its faults are decided like hm_rogue's, its error handler gets the error (GET_ERROR_STATUS)
    and a partition restart shows in its start condition."""
    e = ERROR_IDS[fault.error]
    handler = decision == "PROCESS+handler"
    tables = {"system": {PROCESS_STATE: {e: "PROCESS" if handler else "PARTITION"}},
              "partition": {PROCESS_STATE: {e: "COLD_START"}}}
    args = f"{fault.arg} {AT}" + (" handler" if handler else "")
    path = hm.write_module(tmp_path, f"rogue-{fault.arg}", hm.hm_module(
        args, **tables, program="rogue", system_partition=fault.arg == "write_port"))
    run = run_ske(path, frames=FRAMES, timeout=30)
    ctx = hm.context(run)
    assert run.returncode == 0, ctx
    found = hm.hm_events(run.events)
    assert found, ctx
    at, first = found[0]
    texts = [r.text for r in hm.reports(run.events, hm.FAULTY) if r.index > at]
    if handler:
        assert (first["error"], first["level"], first["action"]) == \
            (fault.error, "PROCESS", "ERROR_HANDLER"), first
        handled = [ROGUE_HANDLER_RE.match(t) for t in texts if ROGUE_HANDLER_RE.match(t)]
        assert handled, ctx
        assert (int(handled[0][1]), int(handled[0][2])) == (fault.apex_code, first["process_id"])
        assert hm.stats_of(run, hm.FAULTY)["restarts"] == 0
    else:
        assert (first["error"], first["level"], first["action"]) == \
            (fault.error, "PARTITION", "COLD_START"), first
        starts = [ROGUE_START_RE.match(t) for t in texts if ROGUE_START_RE.match(t)]
        assert starts and (starts[0][1], starts[0][4]) == (fault.arg, "3"), ctx
        assert hm.stats_of(run, hm.FAULTY)["restarts"] == len(found)
    assert hm.about(run.events, hm.HEALTHY) == hm.about(reference.events, hm.HEALTHY)
