# SPDX-License-Identifier: Apache-2.0
"""The SKE's support of the campaign's oracles: `--trace-port-hashes` (one port_hash event per
source port written in a window: deterministic, changed by a corrupt_output, stopped by a
stuck_output, off by default), and the test switches that break an isolation guarantee on
purpose (each recorded at module start; each does what it says)."""

from __future__ import annotations

import subprocess

MS = 1_000_000
HASHES = "--trace-port-hashes"


def hashes(run, port: str = "SP_STATE") -> list[tuple[int, str, int]]:
    return [(e["t_ns"], e["hash"], e["seq"]) for e in run.of("port_hash", port=port)]


def test_port_hashes_are_deterministic_and_off_by_default(fi, run_fi):
    a, b = run_fi(fi.module(), 6, HASHES), run_fi(fi.module(), 6, HASHES)
    assert hashes(a) and hashes(a) == hashes(b)
    assert [(t, s) for t, _, s in hashes(a)] == [(k * 50 * MS + 5 * MS, k + 1) for k in range(6)]
    (first,) = a.of("port_hash", port="QP_CMD")[:1]
    assert list(first) == ["t_ns", "node", "src", "kind", "partition", "port", "hash", "len",
                           "seq", "messages"]
    assert len(first["hash"]) == 16 and int(first["hash"], 16) >= 0 and first["len"] == 32
    assert not run_fi(fi.module(), 6).of("port_hash")


def test_corrupt_output_changes_the_hashes_of_its_spell(fi, run_fi):
    golden = hashes(run_fi(fi.module(), 6, HASHES))
    run = run_fi(fi.module(), 6, HASHES, "--fault",
                 "corrupt_output:fid=c,at=100ms,until=200ms,partition=producer,port=SP_STATE")
    got = hashes(run)
    assert [(t, s) for t, _, s in got] == [(t, s) for t, _, s in golden]
    changed = [t for (t, h, _), (_, g, _) in zip(got, golden, strict=True) if h != g]
    assert changed == [105 * MS, 155 * MS], run.context()


def test_stuck_output_stops_the_hashes_of_its_spell(fi, run_fi):
    run = run_fi(fi.module(), 8, HASHES, "--fault",
                 "stuck_output:fid=s,at=100ms,until=250ms,partition=producer,port=SP_STATE")
    times = [t for t, _, _ in hashes(run)]
    assert times == [5 * MS, 55 * MS, 255 * MS, 305 * MS, 355 * MS], run.context()
    # The queuing port of the same partition goes on.
    assert len(hashes(run, "QP_CMD")) == 8


def test_test_switches_are_recorded_at_module_start(fi, run_fi):
    run = run_fi(fi.module(), 1, "--test-switch", "overrun-eats-next-window",
                 "--test-switch", "hm-action=faulty:IGNORE")
    switches = [(e["t_ns"], e["name"], e.get("value")) for e in run.of("test_switch")]
    assert switches == [(0, "overrun-eats-next-window", None), (0, "hm-action", "faulty:IGNORE")]
    assert run.index(run.of("test_switch")[0]) == 1  # right after module_start


def test_overrun_eats_next_window(fi, run_fi):
    """faulty spins 15 ms in its 2 ms window [70, 72) ms: not stopped, it holds the CPU until
    about 85 ms, so the sink's window [80, 81) ms starts late, and is eaten whole."""
    spec = "cpu_overrun:fid=o,at=70ms,partition=faulty,value=15"
    normal = run_fi(fi.module(), 3, "--fault", spec)
    assert normal.of("overrun", partition="faulty")
    assert not [e for e in normal.events if e["kind"] == "window_start" and "late_ns" in e]
    run = run_fi(fi.module(), 3, "--fault", spec, "--test-switch", "overrun-eats-next-window")
    assert not run.of("overrun"), run.context()
    (late,) = [e for e in run.events if e["kind"] == "window_start" and "late_ns" in e]
    assert (late["partition"], late["t_ns"]) == ("sink", 80 * MS)
    assert 4 * MS < late["late_ns"] < 8 * MS, late  # 13 ms past 72 ms, less the 8 ms gap
    (end,) = run.of("window_end", partition="sink", frame=1)
    assert "yielded" not in end  # no CPU left for it
    (faulty_end,) = run.of("window_end", partition="faulty", frame=1)
    assert faulty_end["yielded"] is True


def test_hm_action_switch(fi, run_fi):
    spec = "memory_violation:fid=m,at=70ms,until=71ms,partition=faulty"
    (normal,) = run_fi(fi.module(), 3, "--fault", spec).of("hm")
    assert normal["action"] == "IDLE"
    run = run_fi(fi.module(), 3, "--fault", spec, "--test-switch", "hm-action=faulty:WARM_START")
    (hm,) = run.of("hm")
    assert (hm["level"], hm["action"]) == ("PARTITION", "WARM_START"), run.context()
    assert [e["mode"] for e in run.of("mode", partition="faulty") if e["src"] == "ske"] == \
        ["COLD_START", "WARM_START"]


def test_corrupt_port_switch(fi, run_fi):
    """At 107 ms, before the consumer's window at 110 ms reads it, the SKE flips the bytes of
    the producer's latest state: the consumer sees a sequence number that does not follow,
    while the producer's own writes, and their hashes, are those of a run without it."""
    golden = run_fi(fi.module(), 20, HASHES)
    run = run_fi(fi.module(), 20, HASHES, "--test-switch", "corrupt-port=producer.SP_STATE@107ms")
    report = [e["text"] for e in run.of("app_message") if e["src"] == "consumer"]
    want = [e["text"] for e in golden.of("app_message") if e["src"] == "consumer"]
    assert "seq_gaps=0" in want[0] and "seq_gaps=2" in report[0], report
    assert hashes(run) == hashes(golden)
    assert not run.of("fault")


def test_bad_switches_are_refused(fi, tmp_path):
    path = tmp_path / "m.xml"
    path.write_text(fi.module())
    for bad in ("no-such-switch", "hm-action=faulty", "hm-action=nobody:IDLE",
                "hm-action=faulty:RESET", "corrupt-port=producer.QP_CMD@1s",
                "corrupt-port=producer.SP_STATE", "overrun-eats-next-window=1"):
        p = subprocess.run([str(fi.SKE), "--frames", "1", "--test-switch", bad, str(path)],
                           capture_output=True, text=True, env=fi.ske_env(), timeout=30)
        assert p.returncode == 2 and p.stderr.count("\n") == 1, (bad, p.stderr)
        assert p.stderr.startswith(f"ima-ske: error: --test-switch '{bad}': "), p.stderr
