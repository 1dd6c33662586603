# SPDX-License-Identifier: Apache-2.0
"""Tests of running ima-ske (against a stand-in program) and of the schedule summary."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from rich.console import Console

from ima import cli, paths, ske
from ima.errors import ImaError


def render(stats: dict) -> str:
    console = Console(file=io.StringIO(), width=160, color_system=None)
    ske.print_summary(stats, console)
    return console.file.getvalue()


# --- finding the program --------------------------------------------------------------------


def test_missing_ske_binary_says_how_to_build_it(tmp_path, monkeypatch):
    monkeypatch.setenv("IMA_BUILD_DIR", str(tmp_path))
    with pytest.raises(ImaError, match=r"ima-ske not built: run \./ima"):
        paths.ske_binary()


def test_root_comes_from_ima_root_or_the_package_location(monkeypatch):
    monkeypatch.delenv("IMA_ROOT", raising=False)
    monkeypatch.delenv("IMA_BUILD_DIR", raising=False)
    root = paths.repo_root()
    assert (root / "python" / "ima" / "paths.py").is_file()
    assert paths.build_dir() == root / "build"
    monkeypatch.setenv("IMA_ROOT", "/somewhere")
    assert paths.repo_root() == Path("/somewhere")
    assert paths.build_dir() == Path("/somewhere/build")


# --- running it ---------------------------------------------------------------------------------


def test_run_module_passes_options_and_returns_stats(fake_ske, module_xml, sample_stats):
    rc, stats = ske.run_module(
        module_xml,
        frames=7,
        realtime=True,
        trace="t.jsonl",
        node="node2",
        extra_args=["--seed", "3"],
    )
    assert rc == 0
    assert stats == sample_stats
    argv = fake_ske.argv()
    assert argv[0] == "--stats"
    assert argv[2:] == [
        "--frames",
        "7",
        "--realtime",
        "--trace",
        "t.jsonl",
        "--node",
        "node2",
        "--seed",
        "3",
        "--",  # a module path that starts with '-' is no option
        str(module_xml),
    ]


def test_run_module_keeps_stats_where_asked(fake_ske, module_xml, tmp_path):
    kept = tmp_path / "kept.json"
    ske.run_module(module_xml, stats_path=kept)
    assert json.loads(kept.read_text())["module"] == "three_partitions"


def test_quiet_discards_ske_output(fake_ske, module_xml, capfd):
    ske.run_module(module_xml, quiet=True)
    assert "hello" not in capfd.readouterr().out
    ske.run_module(module_xml)
    assert "hello" in capfd.readouterr().out


def test_configuration_error_returns_2_without_stats(fake_ske, module_xml, capfd):
    fake_ske.mode = "config_error"
    assert ske.run_module(module_xml) == (2, None)
    assert "m.xml:3: error: Partition: bad name" in capfd.readouterr().err


def test_missing_module_is_a_configuration_error(fake_ske, tmp_path):
    with pytest.raises(ImaError, match="no such module") as exc:
        ske.run_module(tmp_path / "absent.xml")
    assert exc.value.exit_code == 2


def test_ctrl_c_is_forwarded_and_ske_stops_cleanly(fake_ske, module_xml):
    fake_ske.mode = "wait_int"
    ready = Path(str(fake_ske.log) + ".ready")
    before = signal.getsignal(signal.SIGINT)

    def press_ctrl_c():
        deadline = time.monotonic() + 10
        while not ready.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=press_ctrl_c, daemon=True).start()
    with pytest.raises(ske.SkeInterrupted) as exc:
        ske.run_module(module_xml)
    assert isinstance(exc.value, KeyboardInterrupt)
    assert Path(str(fake_ske.log) + ".signal").read_text() == "SIGINT"
    assert exc.value.returncode == 0
    assert exc.value.stats["exit_reason"] == "signal"
    assert signal.getsignal(signal.SIGINT) is before


# --- the ima run command ------------------------------------------------------------------------


def test_ima_run_json_prints_the_stats(fake_ske, module_xml, capfd, sample_stats):
    assert cli.main(["run", str(module_xml), "--json", "--frames", "3"]) == 0
    out = capfd.readouterr().out
    assert json.loads(out) == sample_stats  # ima-ske's own output stays out of the JSON
    assert "--frames" in fake_ske.argv()


def test_ima_run_config_error_exits_2_with_only_ske_line(fake_ske, module_xml, capfd):
    fake_ske.mode = "config_error"
    assert cli.main(["run", str(module_xml)]) == 2
    captured = capfd.readouterr()
    assert captured.err.strip().splitlines() == [
        f"{module_xml}:3: error: Partition: bad name (rule: name-unique)"
    ]
    assert captured.out == ""


def test_ima_run_runtime_failure_keeps_the_exit_code_and_shows_summary(fake_ske, module_xml, capfd):
    fake_ske.mode = "runtime_failure"
    assert cli.main(["run", str(module_xml)]) == 1
    out = " ".join(capfd.readouterr().out.split())  # the run line may wrap at 80 columns
    assert "speed-up ×200, ended by error" in out


# --- the summary --------------------------------------------------------------------------------


def test_summary_shows_partitions_run_line_and_channels(sample_stats):
    text = render(sample_stats)
    producer = next(line for line in text.splitlines() if "producer" in line)
    # id, name, windows/frame, ms per frame, share of the 50 ms major frame, windows run,
    # CPU ms, overruns, state.
    assert producer.split() == [
        "1",
        "producer",
        "2",
        "15.000",
        "30.0",
        "400",
        "1.235",
        "0",
        "running",
    ]
    assert "[bold]consumer" in text  # names are shown as written, not as markup
    assert "crashed (SIGSEGV)" in text
    assert "Module three_partitions on node1 — major frame 50 ms" in text
    assert "Run: emulated, 200 frames, 10.000 s emulated, 0.050 s wall, speed-up ×200\n" in text
    assert "Window switch: median 7.5 µs, p99 20.1 µs" in text
    assert "Jitter" not in text
    queue = next(line for line in text.splitlines() if "ch_queue" in line)
    assert queue.split() == ["ch_queue", "queuing", "150", "4"]


def test_summary_in_realtime_mode_shows_jitter(sample_stats):
    sample_stats.update(mode="realtime", jitter_us={"median": 3.25, "p99": 18.0, "max": 55.5})
    assert "Jitter: median 3.2 µs, p99 18.0 µs, max 55.5 µs" in render(sample_stats)


def test_summary_tolerates_missing_values(sample_stats):
    sample_stats.update(wall_s=None, window_switch_us=None, channels=[])
    sample_stats["partitions"][0].update(cpu_ns=None, window_ns_per_frame=None)
    text = render(sample_stats)
    assert "s wall, speed-up —" in text
    assert "Channels" not in text
    assert ske.speed_up(sample_stats) is None


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie still answers kill 0; it has exited all the same.
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rsplit(")", 1)[1].split()[0] != "Z"


def test_ske_stops_when_ima_is_killed(fake_ske, module_xml):
    # ima-ske runs in its own process group; a SIGKILLed ima must not leave it running.
    fake_ske.mode = "wait_int"
    ready = Path(str(fake_ske.log) + ".ready")
    script = f"from ima import ske; ske.run_module({str(module_xml)!r})"
    parent = subprocess.Popen([sys.executable, "-c", script])
    try:
        deadline = time.monotonic() + 10
        while not (ready.exists() and ready.read_text()) and time.monotonic() < deadline:
            time.sleep(0.01)
        child = int(ready.read_text())
        parent.kill()
        parent.wait()
        deadline = time.monotonic() + 10
        while _alive(child) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert not _alive(child)
    finally:
        if parent.poll() is None:
            parent.kill()
