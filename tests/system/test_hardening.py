# SPDX-License-Identifier: Apache-2.0
"""The SKE against partitions that attack what it shares with them, and the edges of its
services: port memory a partition tries to shrink, child processes it tries to start, CPU
used between windows, restarts that fail,
queue time-outs against message arrival, samples stamped in the future, output that cannot
be written, a trace on standard output, and why a window overran.

Every module here is built from a small description (partitions, their windows, their
channels); the partition program is sys_hardening, its behaviour chosen by its Arguments."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import pytest

MAF_S = 0.05


@dataclass
class Part:
    """A partition of a test module: its program's arguments, its windows (start, duration
    in seconds) and the XML of its ports."""

    name: str
    arguments: str
    windows: list[tuple[float, float]]
    ports: str = ""
    system: bool = False
    executable: str = "sys_hardening"


@dataclass
class Channel:
    name: str
    source: tuple[str, str]  # (partition, port)
    destination: tuple[str, str]


@dataclass
class Module:
    parts: list[Part]
    channels: list[Channel] = field(default_factory=list)
    time_mode: str = "emulated"
    major_frame_s: float = MAF_S

    def xml(self, name: str) -> str:
        ids = {p.name: i for i, p in enumerate(self.parts, 1)}
        out = [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<ARINC_653_Module xmlns:ima="urn:ima-testbed:arinc653-linux:1" ModuleName="{name}">',
            f'  <ima:Module_Extension Node="node1" TimeMode="{self.time_mode}"/>',
        ]
        for p in self.parts:
            out += [
                f'  <Partition PartitionIdentifier="{ids[p.name]}" PartitionName="{p.name}" '
                f'SystemPartition="{"true" if p.system else "false"}">',
                *(f"    {line.strip()}" for line in p.ports.strip().splitlines()),
                f'    <ima:Linux Executable="{p.executable}" Arguments="{p.arguments}"/>',
                "  </Partition>",
            ]
        out.append(f'  <Module_Schedule MajorFrameSeconds="{self.major_frame_s}">')
        wid = 0
        for p in self.parts:
            out.append(
                f'    <Partition_Schedule PartitionIdentifier="{ids[p.name]}" '
                f'PartitionName="{p.name}" PeriodSeconds="{self.major_frame_s}">'
            )
            for k, (start, duration) in enumerate(p.windows):
                wid += 1
                out.append(
                    f'      <Window_Schedule WindowIdentifier="{wid}" '
                    f'WindowStartSeconds="{start}" WindowDurationSeconds="{duration}" '
                    f'PartitionPeriodStart="{"true" if k == 0 else "false"}"/>'
                )
            out.append("    </Partition_Schedule>")
        out.append("  </Module_Schedule>")
        if self.channels:
            out.append("  <Connection_Table>")
            for i, c in enumerate(self.channels, 1):
                (sp, sport), (dp, dport) = c.source, c.destination
                out += [
                    f'    <Channel ChannelIdentifier="{i}" ChannelName="{c.name}">',
                    f'      <Source><Standard_Partition PartitionIdentifier="{ids[sp]}" '
                    f'PartitionName="{sp}" PortName="{sport}"/></Source>',
                    f'      <Destination><Standard_Partition PartitionIdentifier="{ids[dp]}" '
                    f'PartitionName="{dp}" PortName="{dport}"/></Destination>',
                    "    </Channel>",
                ]
            out.append("  </Connection_Table>")
        out.append("</ARINC_653_Module>")
        return "\n".join(out) + "\n"

    def write(self, folder: Path, name: str) -> Path:
        path = folder / f"{name}.xml"
        path.write_text(self.xml(name))
        return path


def quiet(name: str, start: float, duration: float = 0.005, ports: str = "") -> Part:
    return Part(name, "quiet", [(start, duration)], ports)


def windows_of(run, partition: str) -> list[tuple[dict, dict]]:
    """(window_start, window_end) event pairs of one partition, in trace order."""
    starts = run.of_kind("window_start", partition=partition)
    ends = run.of_kind("window_end", partition=partition)
    return list(zip(starts, ends, strict=True))


def assert_on_time_and_yielded(run, partition: str, frames: int):
    """The partition had its window in every frame, at its configured offset, and handed the
    CPU back in each."""
    (start,) = run.of_kind("module_start")
    table = {w["window"]: w for w in start["windows"] if w["partition"] == partition}
    pairs = windows_of(run, partition)
    assert len(pairs) == frames * len(table), partition
    maf_ns = start["major_frame_ns"]
    for ws, we in pairs:
        assert ws["t_ns"] == ws["frame"] * maf_ns + table[ws["window"]]["offset_ns"], ws
        assert we["yielded"] is True, we
        assert "partition_state" not in ws, ws


def assert_completed(run, frames: int):
    assert run.returncode == 0, run.stderr
    stop = run.events[-1]
    assert (stop["kind"], stop["reason"], stop["frames"]) == ("module_stop", "frames", frames)
    assert run.stats is not None and run.stats["frames"] == frames
    assert run.stats["exit_reason"] == "frames"


def one_line(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1, stderr
    return lines[0]


# ---- a partition shrinks the memory it shares with the SKE -----------------------------------


TRUNCATED_FDS = range(3, 11)  # what sys_hardening tries: its control block (3), ports (4, ...)


def test_partition_truncating_its_port_memory_does_not_kill_the_ske(run_ske, tmp_path):
    """Memory shrunk under the SKE's own mapping would kill it with SIGBUS at its next access
    (the transfer at the end of the truncator's window). A system partition, whose filter
    lets file calls through, tries ftruncate(fd, 0) on descriptors 3..10 twice: from a
    constructor, before the APEX library attaches if it runs first, where it still holds the
    control block (3) and its port (4), sealed at their size; and from main(), when the
    library has closed every descriptor the SKE gave it."""
    frames = 4
    module = Module(
        [
            Part(
                "truncator",
                "truncate",
                [(0.0, 0.005)],
                '<Queuing_Port Name="OUT" MaxMessageSize="16" Direction="SOURCE" '
                'MaxNbMessages="4"/>',
                system=True,
            ),
            quiet(
                "sink",
                0.01,
                ports='<Queuing_Port Name="IN" MaxMessageSize="16" '
                'Direction="DESTINATION" MaxNbMessages="4"/>',
            ),
        ],
        [Channel("shrunk", ("truncator", "OUT"), ("sink", "IN"))],
    )
    run = run_ske(module.write(tmp_path, "truncate"), frames=frames)
    assert run.returncode != -signal.SIGBUS, "ima-ske died of SIGBUS"
    assert_completed(run, frames)
    texts = run.app_messages("truncator")
    assert texts[0] in ("early: the APEX library had not attached",
                        "early: the APEX library had attached"), texts
    before_apex = texts[0].endswith("had not attached")
    sealed = "Operation not permitted"
    closed = "Bad file descriptor"
    expected = [texts[0]]
    for fd in TRUNCATED_FDS:
        # Before the APEX: the control block and the port are open, sealed at their size
        # (EPERM); nothing else is. After it: no descriptor is left to truncate.
        early = sealed if before_apex and fd in (3, 4) else closed
        expected += [f"early ftruncate({fd}): {early}", f"late ftruncate({fd}): {closed}"]
    expected.append("truncated 0 descriptors")
    assert texts == expected
    assert not run.of_kind("hm"), run.of_kind("hm")
    # The port still works: the message it sent afterwards went through whole.
    (channel,) = run.stats["channels"]
    assert channel["messages"] == 1, channel
    assert_on_time_and_yielded(run, "truncator", frames)
    assert_on_time_and_yielded(run, "sink", frames)


# ---- a partition that starts a process of its own ------------------------------------------


def partition_name(pid: int) -> str | None:
    """argv[0] of a process (a partition's is its name), None if it is gone."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().split(b"\0")[0].decode()
    except OSError:
        return None


def test_partition_cannot_fork_and_leaves_no_process(ske_binary, ske_env, tmp_path, run_tag):
    """fork() is refused to every partition, system partitions too (no process or thread
    creation): the call is never made, and the health monitor records an ILLEGAL_REQUEST (the
    defaults: IDLE). At no time does a process of the run have a child of its own, and when
    the run ends no process of it is left."""
    module = Module(
        [
            Part("forker", "fork", [(0.0, 0.005)]),
            Part("sysforker", "fork", [(0.01, 0.005)], system=True),
            quiet("other", 0.02),
        ]
    )
    path = module.write(tmp_path, "fork")
    trace = tmp_path / "trace.jsonl"
    # Standard error to a file: a pipe would stay open as long as a child lived.
    with (tmp_path / "stderr.txt").open("w+") as err:
        proc = subprocess.Popen(
            [str(ske_binary), "--trace", str(trace), str(path)],
            env=ske_env,
            stdout=subprocess.DEVNULL,
            stderr=err,
        )
        try:
            strays = set()

            def only_the_bystander_runs():
                assert proc.poll() is None, "the module stopped on its own"
                procs = run_tag.processes()
                strays.update(p for p in procs if p.pid != proc.pid and p.ppid != proc.pid)
                # A partition's argv[0] is its name; the SKE starts them in module order.
                names = [partition_name(p.pid) for p in procs if p.ppid == proc.pid]
                return names == ["other"] and procs

            # Both forkers idled (their processes ended), the bystander runs on.
            procs = run_tag.wait_until(only_the_bystander_runs, 10, "the forkers are idled")
            assert sorted(Path(p.exe).name for p in procs) == ["ima-ske", "sys_hardening"], procs
            assert not strays, f"a partition's child ran: {strays}"
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=5) == 128 + signal.SIGTERM, err.read()
            run_tag.wait_until(
                lambda: run_tag.processes() == [], 2, "no process of the run is left"
            )
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
            for p in run_tag.processes():
                os.kill(p.pid, signal.SIGKILL)
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    assert events[-1]["kind"] == "module_stop" and events[-1]["reason"] == "signal", events[-1]
    for name, offset in (("forker", 0), ("sysforker", 10_000_000)):
        mine = [e for e in events if e.get("partition") == name or e["src"] == name]
        (denied,) = [e for e in mine if e["kind"] == "hm"]
        assert (denied["src"], denied["error"], denied["level"], denied["action"]) == \
            ("ske", "ILLEGAL_REQUEST", "PARTITION", "IDLE"), denied
        assert (denied["state"], denied["t_ns"]) == ("PARTITION_INIT", offset), denied
        assert "denied" in denied["message"], denied
        assert not [e for e in mine if e["kind"] == "app_message"], "fork() returned"
        assert not [e for e in mine if e["kind"] == "partition_exit"], mine
        idle = [e for e in mine if e["kind"] == "mode" and e["src"] == "ske"
                and e.get("reason") == "health monitor"]
        assert [(e["t_ns"], e["mode"]) for e in idle] == [(offset, "IDLE")], idle
        later = [e for e in mine if e["kind"] == "window_start" and e["frame"] >= 1]
        assert later and all(e.get("partition_state") == "idle" for e in later), later
    other = [e for e in events if e["kind"] == "window_start" and e["partition"] == "other"]
    assert other and all("partition_state" not in e for e in other)


def test_partition_forking_before_it_attaches_stops_the_start(ske_binary, ske_env, tmp_path,
                                                             run_tag):
    """The same fork() from a constructor of the first priority a program may use, which the
    APEX library's attachment has too. Run before the attachment (as the program's own objects,
    linked ahead of the library, are), the SKE's loader filter refuses it: SIGSYS, which
    nothing handles yet, so the partition dies before attaching and the module does not start.
    Run after it, the partition's own filter refuses it, as in main(). Either way no child
    runs, and no process of the run is left."""
    module = Module([Part("forker", "fork_early", [(0.0, 0.005)]), quiet("other", 0.01)])
    trace = tmp_path / "trace.jsonl"
    r = subprocess.run(
        [str(ske_binary), "--frames", "2", "--trace", str(trace),
         str(module.write(tmp_path, "fork_early"))],
        env=ske_env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    said = [e["text"] for e in events if e["kind"] == "app_message" and e["src"] == "forker"]
    if said == ["fork_early: the APEX library had attached"]:
        assert r.returncode == 0, r.stderr
        (denied,) = [e for e in events if e["kind"] == "hm"]
        assert (denied["partition"], denied["error"], denied["action"]) == \
            ("forker", "ILLEGAL_REQUEST", "IDLE"), denied
    else:
        assert r.returncode == 1 and said == [], (r.stderr, said)
        line = one_line(r.stderr)
        assert re.fullmatch(
            r"ima-ske: error: partition 'forker' \(\S*/sys_hardening\) was killed before "
            rf"attaching to the SKE \(signal {int(signal.SIGSYS)}\)",
            line,
        ), line
        assert [e["kind"] for e in events] == ["module_stop"], events
        assert events[0]["reason"] == "error", events[0]
    run_tag.wait_until(lambda: run_tag.processes() == [], 2, "no process of the run is left")


# ---- a partition that computes between its windows -------------------------------------------


def test_cpu_used_between_windows_is_an_overrun(run_ske, tmp_path):
    """The rogue hands the CPU back at once in each window but computes on while the burner
    computes in its own window: the SKE sees the CPU the rogue used between its windows."""
    frames = 6
    module = Module(
        [
            Part("rogue", "outside", [(0.0, 0.005)]),
            Part("burner", "burn 12", [(0.005, 0.02)]),
            quiet("other", 0.03),
        ]
    )
    run = run_ske(module.write(tmp_path, "outside"), frames=frames)
    assert_completed(run, frames)

    outside = run.of_kind("overrun", cause="outside_window")
    assert outside, "no overrun with cause outside_window"
    rogue_starts = {(ws["frame"], ws["window"]): ws["t_ns"] for ws, _ in windows_of(run, "rogue")}
    for o in outside:
        assert o["partition"] == "rogue" and o["action"] == "reported", o
        # Reported as the rogue's next window starts, from the first window after the one in
        # which it first handed the CPU back.
        assert o["t_ns"] == rogue_starts[(o["frame"], o["window"])] and o["frame"] >= 1, o
    # The burner leaves the rogue ~12 ms of wall time between its windows; a fraction of it
    # is already over the SKE's limit, so every later window of the rogue shows it.
    assert len(outside) >= frames - 2, outside

    hm = run.of_kind("hm", error="WINDOW_OVERRUN")
    assert len(hm) == len(outside), hm
    for e in hm:
        assert e["partition"] == "rogue" and e["level"] == "PARTITION", e
        assert e["action"] == "IGNORE", e  # the default Partition HM table
        assert "used CPU between its windows" in e["message"], e

    # The others' windows start on time and end by their own hand-over.
    assert_on_time_and_yielded(run, "burner", frames)
    assert_on_time_and_yielded(run, "other", frames)
    stats = {p["name"]: p for p in run.stats["partitions"]}
    assert stats["rogue"]["overruns"] == len(outside)
    assert stats["rogue"]["cpu_outside_windows_ns_max"] > 2_000_000
    assert stats["burner"]["overruns"] == 0 and stats["other"]["overruns"] == 0


# ---- a restart that fails ------------------------------------------------------------------


def test_failed_restart_stays_with_its_partition(run_ske, tmp_path):
    frames = 5
    flag = tmp_path / "started-once"
    module = Module(
        [
            quiet("before", 0.0),
            Part("restarter", f"restart {flag}", [(0.01, 0.005)], system=True),
            quiet("after", 0.02),
        ]
    )
    run = run_ske(module.write(tmp_path, "restart"), frames=frames)
    assert_completed(run, frames)
    assert flag.exists()

    (restart,) = run.of_kind("mode", src="ske", partition="restarter", reason="SET_PARTITION_MODE")
    assert restart["mode"] == "COLD_START", restart
    (failed,) = run.of_kind("start_failed")
    assert failed["partition"] == "restarter", failed
    assert failed["t_ns"] == restart["t_ns"] == 15_000_000, failed  # end of its first window
    assert "before attaching" in failed["reason"] and "status 5" in failed["reason"], failed

    # It stays down for the rest of the run; its windows still come, empty, and say why.
    pairs = windows_of(run, "restarter")
    assert len(pairs) == frames
    for ws, we in pairs[1:]:
        assert ws["partition_state"] == "crashed", ws
        assert "yielded" not in we, we
    for name in ("before", "after"):
        assert_on_time_and_yielded(run, name, frames)
    stats = {p["name"]: p for p in run.stats["partitions"]}
    assert stats["restarter"]["restarts"] == 1 and stats["restarter"]["state"] == "crashed"


# ---- queuing: the message that arrived before the time-out wins --------------------------


def test_queued_message_arriving_before_the_time_out_is_received(run_ske, tmp_path):
    """The receiver waits from 0 ms with time-outs of 40 ms (Q1_IN) and 25 ms (Q2_IN); the
    sender's messages arrive at the end of its window, 30 ms. The receiver runs again at
    50 ms, when both time-outs are past: the message that arrived first is received, the
    time-out that came first wins."""
    frames = 2
    dst = (
        '<Queuing_Port Name="Q{n}_IN" MaxMessageSize="16" Direction="DESTINATION" '
        'MaxNbMessages="4"/>'
    )
    src = '<Queuing_Port Name="Q{n}" MaxMessageSize="16" Direction="SOURCE" MaxNbMessages="4"/>'
    module = Module(
        [
            Part(
                "receiver", "qrecv 40 25", [(0.0, 0.01)], "\n".join(dst.format(n=n) for n in (1, 2))
            ),
            Part("sender", "qsend", [(0.02, 0.01)], "\n".join(src.format(n=n) for n in (1, 2))),
        ],
        [
            Channel("one", ("sender", "Q1"), ("receiver", "Q1_IN")),
            Channel("two", ("sender", "Q2"), ("receiver", "Q2_IN")),
        ],
    )
    run = run_ske(module.write(tmp_path, "queue_time_out"), frames=frames)
    assert_completed(run, frames)
    assert run.app_messages("sender") == ["sent at 20000000"]
    got = sorted(run.app_messages("receiver"))
    assert got == [
        "Q1_IN: NO_ERROR 'one' waited from 0 to 50000000",
        "Q2_IN: TIMED_OUT waited from 0 to 50000000",
    ], got


# ---- sampling: a stamp from the future -----------------------------------------------------


@pytest.mark.parametrize(
    ("arguments", "validity"),
    [("sample", "VALID"), ("future", "INVALID")],
    ids=["stamped-now", "stamped-in-the-future"],
)
def test_sample_stamped_in_the_future_is_invalid(run_ske, tmp_path, arguments, validity):
    """The source writes a message at 0 ms; the reader reads it at 20 ms, within the 100 ms
    refresh period. Stamped far in the future by the source, it is not valid."""
    port = '<Sampling_Port Name="{}" MaxMessageSize="16" Direction="{}" RefreshRateSeconds="0.1"/>'
    module = Module(
        [
            Part("writer", arguments, [(0.0, 0.01)], port.format("S", "SOURCE")),
            Part("reader", "read", [(0.02, 0.01)], port.format("S_IN", "DESTINATION")),
        ],
        [Channel("state", ("writer", "S"), ("reader", "S_IN"))],
    )
    run = run_ske(module.write(tmp_path, f"sample_{arguments}"), frames=1)
    assert_completed(run, 1)
    if arguments == "future":
        assert run.app_messages("writer") == [f"future: message 1 stamped {(2**63 - 1) // 2}"]
    assert run.app_messages("reader") == [f"S_IN: NO_ERROR {validity} 'sample'"]
    (event,) = run.of_kind("port", partition="reader")
    assert (event["port"], event["event"]) == ("S_IN", validity.lower()), event


# ---- output that cannot be written -----------------------------------------------------------


@pytest.mark.parametrize(
    ("option", "target", "what", "why"),
    [
        ("--trace", "/dev/full", "trace", "No space left on device"),
        ("--stats", "/nonexistent/dir/s.json", "statistics", "No such file or directory"),
    ],
    ids=["trace-disk-full", "stats-no-such-folder"],
)
def test_output_that_cannot_be_written_fails_the_run(
    ske_binary, ske_env, tmp_path, option, target, what, why
):
    path = Module([quiet("only", 0.0)]).write(tmp_path, "output")
    r = subprocess.run(
        [str(ske_binary), "--frames", "2", option, target, str(path)],
        env=ske_env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert r.returncode == 1, r.stderr
    says = f"the {what} {target} could not be written: {why}"
    assert one_line(r.stderr) == f"ima-ske: error: {says}"


# ---- the trace on standard output ------------------------------------------------------------


def test_trace_on_stdout_stays_json_when_a_partition_prints(ske_binary, ske_env, tmp_path):
    path = Module([Part("printer", "print", [(0.0, 0.005)]), quiet("other", 0.01)]).write(
        tmp_path, "print"
    )
    r = subprocess.run(
        [str(ske_binary), "--frames", "3", "--trace", "-", str(path)],
        env=ske_env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    events = []
    for n, line in enumerate(lines, 1):
        try:
            events.append(json.loads(line))
        except json.JSONDecodeError:
            pytest.fail(f"standard output line {n} is not JSON: {line!r}")
    assert events[0]["kind"] == "module_start" and events[-1]["kind"] == "module_stop"
    assert len(events) > 10
    # What the partition printed is not lost: it goes where diagnostics go.
    assert "sys_hardening: a line on standard output" in r.stderr


# ---- why a window overran ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("time_mode", "cause"), [("emulated", "cpu_budget"), ("realtime", "window_end")]
)
def test_overrun_says_its_cause(run_ske, tmp_path, time_mode, cause):
    frames = 4
    module = Module(
        [Part("spinner", "spin", [(0.0, 0.005)]), quiet("other", 0.01)],
        time_mode=time_mode,
        major_frame_s=0.02,
    )
    run = run_ske(module.write(tmp_path, f"spin_{time_mode}"), frames=frames)
    assert_completed(run, frames)
    overruns = run.of_kind("overrun")
    spinner = [o for o in overruns if o["partition"] == "spinner"]
    assert len(spinner) == frames, overruns
    assert all(o["action"] == "stopped" for o in spinner), spinner
    # Every overrun says why, the spinner's and any other (in real time, the host's load can
    # make the quiet partition's first window overrun too).
    assert [o.get("cause") for o in overruns] == [cause] * len(overruns), overruns


# ---- the end of the clock --------------------------------------------------------------------


def test_module_time_stops_at_the_end_of_the_clock(run_ske, tmp_path):
    """A 9e9 s major frame: the second frame would end past the 64-bit nanosecond clock
    (about 292 years), so the run ends after the first instead of wrapping to negative
    times."""
    module = Module([quiet("only", 0.0)], major_frame_s=9_000_000_000)
    run = run_ske(module.write(tmp_path, "end_of_time"), frames=4)
    assert run.returncode == 0, run.stderr
    stop = run.events[-1]
    assert (stop["kind"], stop["reason"], stop["frames"]) == ("module_stop", "end_of_time", 1)
    assert stop["t_ns"] == 9_000_000_000 * 10**9
    times = [e["t_ns"] for e in run.events]
    assert times == sorted(times) and times[0] >= 0, times
    assert len(run.of_kind("window_start")) == 1
    assert run.stats["exit_reason"] == "end_of_time"


# ---- a partition writes garbage where the SKE reads it --------------------------------------


def test_garbage_in_the_shared_memory_is_refused_field_by_field(run_ske, tmp_path):
    """The scribbler writes, through its own mappings, events it could not have sent, queue
    indices out of range, then an event ring claiming more than it holds and a count of lost
    events. The SKE traces only what makes sense (a time outside the window marked suspect,
    a text cut to its size), drops a source queue's corrupt content with a `port` event,
    resynchronises a destination's consumer index, skips an impossible ring, and runs on."""
    frames = 4
    q = '<Queuing_Port Name="{}" MaxMessageSize="16" Direction="{}" MaxNbMessages="4"/>'
    module = Module(
        [
            Part("scribbler", "scribble", [(0.0, 0.01)], "\n".join(
                [q.format("Q", "SOURCE"), q.format("Q1_IN", "DESTINATION"),
                 q.format("Q2_IN", "DESTINATION")])),
            Part("sink", "qsend", [(0.02, 0.01)], "\n".join(
                [q.format("Q1", "SOURCE"), q.format("Q2", "SOURCE"),
                 q.format("Q_IN", "DESTINATION")])),
        ],
        [
            Channel("back", ("scribbler", "Q"), ("sink", "Q_IN")),
            Channel("one", ("sink", "Q1"), ("scribbler", "Q1_IN")),
            Channel("two", ("sink", "Q2"), ("scribbler", "Q2_IN")),
        ],
    )
    run = run_ske(module.write(tmp_path, "scribble"), frames=frames)
    assert_completed(run, frames)
    mine = [e for e in run.events if e["src"] == "scribbler"]
    messages = [e for e in mine if e["kind"] == "app_message"]
    future, long, ordered = messages
    assert future["text"] == "from the future" and future["suspect_time"] is True, future
    assert future["t_ns"] == 0 and future["reported_t_ns"] == 1000000000000, future
    assert long["text"] == "long" + "x" * 124 and "suspect_time" not in long, long
    assert ordered["text"] == "ring in order" and ordered["t_ns"] == 2 * 50000000, ordered
    # Nothing else it wrote by hand reached the trace: its modes are the library's own.
    assert [(e["mode"], e["from"]) for e in mine if e["kind"] == "mode"] == [
        ("NORMAL", "COLD_START")]
    assert not [e for e in mine if e["kind"] in ("hm", "port")], mine
    (corrupt,) = run.of_kind("port", event="corrupt")
    assert (corrupt["partition"], corrupt["port"], corrupt["t_ns"]) == ("scribbler", "Q", 10000000)
    (dropped,) = run.of_kind("events_dropped")
    assert (dropped["partition"], dropped["count"]) == ("scribbler", 3), dropped
    # The sink's messages reached the scribbler's queues, the corrupt index notwithstanding.
    assert run.app_messages("sink") == ["sent at 20000000"]
    assert not run.of_kind("port", event="overflow")
