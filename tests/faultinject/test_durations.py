# SPDX-License-Identifier: Apache-2.0
"""The durations of faultinject/include/fi/spec.h as ima-ske applies them, with the SKE keeping
the bookkeeping across restarts of the partition: a permanent event fault happens again in
every new process (a crash loop), a transient one once, an intermittent one once per spell; a
state fault is active over its spells and cleared after, applied again in a process restarted
in the middle of its spell; a spell that finds its partition not running is refused; a module
reset restarts every partition at a major frame's start."""

from __future__ import annotations

MS = 1_000_000
WARM = {2: {"MEMORY_VIOLATION": "WARM_START"}}


def applied(run, fid: str | None = None) -> list[int]:
    return [e["t_ns"] for e in run.of("fault") if e["state"] == "applied"
            and (fid is None or e["fid"] == fid)]


def test_permanent_is_a_crash_loop(fi, run_fi):
    run = run_fi(fi.module(partition=WARM), 6, "--fault",
                 "memory_violation:fid=p,at=70ms,partition=faulty")
    # Every new process commits it again at the first release it runs: 70, 120, ... 270 ms.
    times = [70 * MS + k * 50 * MS for k in range(5)]
    assert applied(run) == times, run.context()
    hm = run.of("hm", partition="faulty")
    assert [(e["t_ns"], e["action"]) for e in hm] == [(t, "WARM_START") for t in times]
    starts = [e["t_ns"] for e in run.of("mode", partition="faulty") if e["mode"] == "WARM_START"]
    assert starts == times


def test_transient_happens_once(fi, run_fi):
    run = run_fi(fi.module(partition=WARM), 6, "--fault",
                 "memory_violation:fid=t,at=70ms,until=1s,partition=faulty")
    assert applied(run) == [70 * MS], run.context()
    assert len(run.of("hm", partition="faulty")) == 1
    # The new process runs on, normally.
    assert [e["t_ns"] for e in run.of("mode", partition="faulty", mode="NORMAL")] == [20 * MS, 120 * MS]


def test_intermittent_once_per_spell(fi, run_fi):
    """Spells [70, 80), [170, 180), [270, 280) ms; the handler STARTs the faulted process."""
    run = run_fi(fi.module(faulty="none 100000 handler", system={2: {"MEMORY_VIOLATION": "PROCESS"}}),
                 7, "--fault", "memory_violation:fid=i,at=70ms,period=100ms,on=10ms,partition=faulty")
    assert applied(run) == [70 * MS, 170 * MS, 270 * MS], run.context()
    hm = run.of("hm", partition="faulty")
    assert [(e["t_ns"], e["action"]) for e in hm] == [(t, "ERROR_HANDLER") for t in applied(run)]


def test_intermittent_state_fault_is_cleared_after_each_spell(fi, run_fi):
    run = run_fi(fi.module(), 8, "--fault",
                 "stuck_output:fid=s,at=100ms,period=150ms,on=100ms,partition=producer,port=SP_STATE")
    got = [(e["t_ns"], e["state"]) for e in run.of("fault")]
    assert got == [(100 * MS, "applied"), (200 * MS, "cleared"), (250 * MS, "applied"),
                   (350 * MS, "cleared")], run.context()


def test_state_fault_applied_again_after_a_restart(fi, run_fi):
    """A permanent hang: every window overruns, COLD_START each time; each new process hangs
    again, without a new fault event (the fault goes on)."""
    run = run_fi(fi.module(system={2: {"WINDOW_OVERRUN": "PARTITION"}},
                           partition={2: {"WINDOW_OVERRUN": "COLD_START"}}),
                 5, "--fault", "partition_hang:fid=h,at=70ms,partition=faulty")
    assert [(e["t_ns"], e["state"]) for e in run.of("fault")] == [(70 * MS, "applied")]
    hm = run.of("hm", partition="faulty")
    assert [(e["t_ns"], e["error"], e["action"]) for e in hm] == \
        [(t * MS, "WINDOW_OVERRUN", "COLD_START") for t in (72, 122, 172, 222)], run.context()


def test_transient_hang_cleared_by_the_restarted_process(fi, run_fi):
    run = run_fi(fi.module(system={2: {"WINDOW_OVERRUN": "PARTITION"}},
                           partition={2: {"WINDOW_OVERRUN": "COLD_START"}}),
                 5, "--fault", "partition_hang:fid=h,at=70ms,until=100ms,partition=faulty")
    assert [(e["t_ns"], e["state"], e["src"]) for e in run.of("fault")] == \
        [(70 * MS, "applied", "faulty"), (120 * MS, "cleared", "faulty")], run.context()
    assert len(run.of("overrun", partition="faulty")) == 1


def test_spell_of_a_partition_not_running_is_refused(fi, run_fi):
    run = run_fi(fi.module(), 5, "--fault", "partition_crash:fid=a,at=70ms,partition=faulty",
                 "--fault", "numeric_error:fid=b,at=150ms,partition=faulty")
    (refused,) = [e for e in run.of("fault") if e["state"] == "refused"]
    # Idled at 72 ms (PARTITION_EXIT, default IDLE); refused at its next window after 150 ms.
    assert (refused["fid"], refused["t_ns"], refused["src"]) == ("b", 170 * MS, "ske"), run.context()
    assert "not running (idle)" in refused["detail"]


def test_module_reset(fi, run_fi):
    run = run_fi(fi.module(), 4, "--fault", "module_reset:fid=r,at=60ms")
    (fault,) = run.of("fault")
    assert (fault["t_ns"], fault["src"], fault["target"], fault["state"]) == \
        (100 * MS, "ske", "module", "applied"), run.context()
    resets = [e for e in run.of("mode") if e.get("reason") == "module reset"]
    assert {e["partition"] for e in resets} == {"producer", "consumer", "faulty", "sink"}
    assert all(e["t_ns"] == 100 * MS and run.index(e) > run.index(fault) for e in resets)
    # Once: permanent, but a module that reset at every frame would never run.
    assert len(resets) == 4


def test_runs_with_faults_write_identical_traces(fi, run_fi):
    """Emulated time: faults fire at service calls, at module times; nothing of the host
    reaches the trace."""
    faults = ["--fault", "partition_hang:fid=h,at=70ms,until=130ms,partition=faulty",
              "--fault", "corrupt_output:fid=c,at=100ms,period=100ms,on=50ms,partition=producer,port=SP_STATE",
              "--fault", "numeric_error:fid=n,at=200ms,period=100ms,on=10ms,partition=consumer,process=sample",
              "--fault", "memory_exhaustion:fid=m,at=300ms,partition=sink",
              "--fault", "module_reset:fid=r,at=400ms", "--trace-port-hashes"]
    a, b = run_fi(fi.module(), 12, *faults), run_fi(fi.module(), 12, *faults)
    assert a.returncode == 0 and len(a.of("fault")) >= 8, a.context()
    assert a.trace == b.trace
