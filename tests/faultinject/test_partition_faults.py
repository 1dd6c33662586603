# SPDX-License-Identifier: Apache-2.0
"""Every fault class a partition commits itself (`ima-ske --fault`, the APEX library's fault
hook): it fires at its time, in the faulty partition's process "rogue" (released at 20 ms into
each 50 ms frame), its `fault` event comes first, and the health monitor sees what it should:
the error the real detection path reports, decided as the module's tables say, with the
default tables and with tables that use every level and action. The output and queue faults,
which no health monitor sees, show in what the other partitions see."""

from __future__ import annotations

import pytest

MS = 1_000_000
AT = 70 * MS  # a release of "rogue" (frame 1)

# class: (extra parameters, error, when it is decided, (level, action) with default tables)
CASES = {
    "partition_crash": ("", "PARTITION_EXIT", 72 * MS, ("PARTITION", "IDLE")),
    "partition_hang": ("", "WINDOW_OVERRUN", 72 * MS, ("PARTITION", "IGNORE")),
    "cpu_overrun": ("", "WINDOW_OVERRUN", 72 * MS, ("PARTITION", "IGNORE")),
    "memory_violation": ("", "MEMORY_VIOLATION", AT, ("PARTITION", "IDLE")),
    "numeric_error": ("", "NUMERIC_ERROR", AT, ("PARTITION", "IDLE")),
    "stack_overflow": ("", "STACK_OVERFLOW", AT, ("PARTITION", "IDLE")),
    "illegal_request": ("", "ILLEGAL_REQUEST", AT, ("PARTITION", "IDLE")),
    "application_error": ("", "APPLICATION_ERROR", AT, ("PARTITION", "IDLE")),
    "deadline_miss": (",process=rogue", "DEADLINE_MISSED", 120 * MS, ("PARTITION", "IGNORE")),
    "memory_exhaustion": ("", "MEMORY_VIOLATION", AT, ("PARTITION", "IDLE")),
    "foreign_port_write": (",port=ROGUE_IN", "MEMORY_VIOLATION", AT, ("PARTITION", "IDLE")),
}

# Tables that use every level and action; the faulty partition has an error handler.
SYSTEM = {2: {"DEADLINE_MISSED": "PROCESS", "APPLICATION_ERROR": "PROCESS",
              "ILLEGAL_REQUEST": "MODULE", "NUMERIC_ERROR": "PARTITION",
              "STACK_OVERFLOW": "PARTITION", "MEMORY_VIOLATION": "PARTITION",
              "WINDOW_OVERRUN": "PARTITION", "PARTITION_EXIT": "PARTITION"}}
MODULE = {2: {"ILLEGAL_REQUEST": "RESET"}}
PARTITION = {2: {"NUMERIC_ERROR": "WARM_START", "STACK_OVERFLOW": "COLD_START",
                 "MEMORY_VIOLATION": "COLD_START", "WINDOW_OVERRUN": "COLD_START",
                 "PARTITION_EXIT": "WARM_START"}}
WITH_TABLES = {
    "partition_crash": ("PARTITION", "WARM_START"),
    "partition_hang": ("PARTITION", "COLD_START"),
    "cpu_overrun": ("PARTITION", "COLD_START"),
    "memory_violation": ("PARTITION", "COLD_START"),
    "numeric_error": ("PARTITION", "WARM_START"),
    "stack_overflow": ("PARTITION", "COLD_START"),
    "illegal_request": ("MODULE", "RESET"),
    "application_error": ("PROCESS", "ERROR_HANDLER"),
    "deadline_miss": ("PROCESS", "ERROR_HANDLER"),
    "memory_exhaustion": ("PARTITION", "COLD_START"),
    "foreign_port_write": ("PARTITION", "COLD_START"),
}


def check_fires_first(run, cls: str, fid: str, target: str) -> tuple[dict, int]:
    """The fault's applied event, at its time, before any hm event of the faulty partition."""
    (fault,) = [e for e in run.of("fault", fid=fid) if e["state"] == "applied"][:1] or [None]
    assert fault, run.context()
    assert (fault["t_ns"], fault["src"], fault["class"], fault["target"]) == (AT, "faulty", cls, target)
    assert list(fault) == ["t_ns", "node", "src", "kind", "fid", "class", "target", "state", "detail"]
    first = run.index(fault)
    assert not [e for e in run.events[:first] if e["kind"] == "hm"], run.context()
    return fault, first


@pytest.mark.parametrize("cls", sorted(CASES))
def test_fires_and_the_health_monitor_sees_it(fi, run_fi, cls):
    extra, error, decided_at, expected = CASES[cls]
    run = run_fi(fi.module(), 4, "--fault", f"{cls}:fid=f1,at=70ms,partition=faulty{extra}")
    assert run.returncode == 0, run.context()
    target = "faulty.rogue" if "process" in extra else "faulty.ROGUE_IN" if "port" in extra else "faulty"
    fault, first = check_fires_first(run, cls, "f1", target)
    hm = [e for e in run.of("hm", partition="faulty")]
    assert hm, run.context()
    assert (hm[0]["error"], hm[0]["t_ns"], (hm[0]["level"], hm[0]["action"])) == \
        (error, decided_at, expected), run.context()
    assert run.index(hm[0]) > first
    if cls == "partition_crash":
        (exit_,) = run.of("partition_exit", partition="faulty")
        assert first < run.index(exit_) < run.index(hm[0]) and exit_["signal"] == "ABRT"
    if cls == "partition_hang":  # spins for ever: every later window of it overruns
        assert [e["t_ns"] for e in hm] == [72 * MS, 122 * MS, 172 * MS], run.context()
        assert len(run.of("overrun", partition="faulty")) == 3
    if cls == "cpu_overrun":  # longer than its window by default: one overrun, then it yields
        assert len(hm) == 1 and len(run.of("overrun", partition="faulty")) == 1, run.context()
    if cls == "application_error":
        assert hm[0]["message"] == "fault f1: application_error injected"
    if cls == "deadline_miss":
        assert hm[0]["process"] == "rogue" and "TIMED_WAIT" in fault["detail"]
    if cls == "memory_exhaustion":
        assert "MiB until malloc refused" in fault["detail"]


@pytest.mark.parametrize("cls", sorted(WITH_TABLES))
def test_decided_as_the_tables_say(fi, run_fi, cls):
    extra = CASES[cls][0]
    text = fi.module(faulty="none 100000 handler", system=SYSTEM, module_table=MODULE,
                     partition=PARTITION)
    run = run_fi(text, 4, "--fault", f"{cls}:fid=t,at=70ms,until=71ms,partition=faulty{extra}")
    assert run.returncode == 0, run.context()
    check_fires_first(run, cls, "t", run.of("fault")[0]["target"])
    hm = run.of("hm", partition="faulty")
    assert hm and (hm[0]["error"], hm[0]["level"], hm[0]["action"]) == \
        (CASES[cls][1], *WITH_TABLES[cls]), run.context()
    if WITH_TABLES[cls][1] == "RESET":  # every partition starts again at the next frame
        resets = [e for e in run.of("mode") if e.get("reason") == "module reset"]
        assert {e["partition"] for e in resets} == {"producer", "consumer", "faulty", "sink"}
        assert {e["t_ns"] for e in resets} == {100 * MS}
    if WITH_TABLES[cls][0] == "PROCESS":  # the handler read it
        assert any(e["src"] == "faulty" and e["text"].startswith("handler: error")
                   for e in run.of("app_message")), run.context()
    # Transient: once, whatever the restarts.
    assert len([e for e in run.of("fault") if e["state"] == "applied"]) == 1, run.context()


def test_illegal_request_of_a_system_partition(fi, run_fi):
    """A system partition may open sockets: its illegal request is a signal to another
    process, which no partition may send."""
    run = run_fi(fi.module(faulty_system=True), 3, "--fault",
                 "illegal_request:fid=s,at=70ms,partition=faulty")
    check_fires_first(run, "illegal_request", "s", "faulty")
    (hm,) = run.of("hm", partition="faulty")
    assert hm["error"] == "ILLEGAL_REQUEST" and "kill" in run.of("fault")[0]["detail"]


def test_the_named_process_commits_it(fi, run_fi):
    """process=receive: the consumer's aperiodic process, not its periodic "sample"."""
    run = run_fi(fi.module(), 4, "--fault",
                 "memory_violation:fid=p,at=60ms,partition=consumer,process=receive")
    (hm,) = run.of("hm", partition="consumer")
    assert (hm["process"], hm["error"]) == ("receive", "MEMORY_VIOLATION"), run.context()
    (fault,) = run.of("fault")
    assert fault["target"] == "consumer.receive" and fault["t_ns"] == hm["t_ns"]


def test_deadline_miss_of_a_process_without_deadline_is_refused(fi, run_fi):
    run = run_fi(fi.module(), 3, "--fault",
                 "deadline_miss:fid=d,at=60ms,partition=consumer,process=receive")
    (fault,) = run.of("fault")
    assert (fault["state"], fault["src"]) == ("refused", "consumer") and "no deadline" in fault["detail"]
    assert not run.of("hm"), run.context()


def consumer_report(run) -> str:
    (text,) = [e["text"] for e in run.of("app_message") if e["src"] == "consumer"]
    return text


def test_corrupt_output_reaches_the_readers(fi, run_fi):
    """From `at`, every write of the producer's state is corrupted (XOR 0x5A): its readers see
    sequence numbers that do not follow; no health monitor sees anything."""
    golden = run_fi(fi.module(), 20)
    run = run_fi(fi.module(), 20, "--fault",
                 "corrupt_output:fid=c,at=100ms,until=200ms,partition=producer,port=SP_STATE")
    assert "seq_gaps=0" in consumer_report(golden)
    assert "seq_gaps=0" not in consumer_report(run), consumer_report(run)
    states = [(e["t_ns"], e["state"], e["src"]) for e in run.of("fault")]
    assert states == [(100 * MS, "applied", "producer"), (200 * MS, "cleared", "producer")]
    assert not run.of("hm")


def test_stuck_output_goes_stale(fi, run_fi):
    """The producer's state is not written from `at` on: its readers see it INVALID once it is
    older than its refresh period (100 ms), and VALID again after the spell."""
    run = run_fi(fi.module(), 10, "--fault",
                 "stuck_output:fid=s,at=100ms,until=300ms,partition=producer,port=SP_STATE")
    seen = [(e["t_ns"], e["event"]) for e in run.of("port", partition="consumer")]
    # Last write at 50 ms: older than 100 ms at the consumer's window at 160 ms.
    assert seen == [(10 * MS, "valid"), (160 * MS, "invalid"), (310 * MS, "valid")], seen


def test_queuing_flood_overflows_the_destination(fi, run_fi):
    """The faulty partition fills its source queue (4 messages) in each of its windows of the
    spell; the destination nobody reads holds 4: every later message overflows it."""
    run = run_fi(fi.module(), 8, "--fault",
                 "queuing_flood:fid=q,at=100ms,until=250ms,partition=faulty,port=ROGUE_OUT")
    overflows = [e["t_ns"] for e in run.of("port", event="overflow")]
    # Flooded in the windows at 120, 170 and 220 ms; the first fills the destination.
    assert overflows == [172 * MS] * 4 + [222 * MS] * 4, run.context()
    states = [(e["t_ns"], e["state"]) for e in run.of("fault")]
    assert states == [(120 * MS, "applied"), (270 * MS, "cleared")]
