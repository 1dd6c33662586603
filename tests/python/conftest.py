# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures for the ima CLI tests: a stand-in ima-ske program in a temporary build tree."""

from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path

import pytest

SAMPLE_STATS = {
    "module": "three_partitions",
    "node": "node1",
    "mode": "emulated",
    "major_frame_ns": 50_000_000,
    "frames": 200,
    "emulated_ns": 10_000_000_000,
    "wall_s": 0.05,
    "exit_reason": "frames",
    "partitions": [
        {
            "id": 1,
            "name": "producer",
            "windows_per_frame": 2,
            "window_ns_per_frame": 15_000_000,
            "windows": 400,
            "cpu_ns": 1_234_567,
            "overruns": 0,
            "state": "running",
            "exit_status": None,
            "cpu_outside_windows_ns_max": 12_000,
        },
        {
            "id": 2,
            "name": "[bold]consumer",
            "windows_per_frame": 1,
            "window_ns_per_frame": 10_000_000,
            "windows": 200,
            "cpu_ns": 2_000_000,
            "overruns": 3,
            "state": "crashed",
            "exit_status": "SIGSEGV",
            "cpu_outside_windows_ns_max": None,
        },
    ],
    "window_switch_us": {"count": 799, "median": 7.5, "p99": 20.1, "max": 40.2},
    "jitter_us": None,
    "channels": [
        {"id": 1, "name": "ch_samples", "kind": "sampling", "messages": 200, "overflows": 0},
        {"id": 2, "name": "ch_queue", "kind": "queuing", "messages": 150, "overflows": 4},
    ],
}

# Behaviour chosen by FAKE_SKE_MODE; it records its arguments in FAKE_SKE_LOG.
_FAKE_SKE = """\
    import json, os, signal, sys, time

    args = sys.argv[1:]
    with open(os.environ["FAKE_SKE_LOG"], "w") as f:
        json.dump(args, f)
    mode = os.environ.get("FAKE_SKE_MODE", "ok")
    stats_path = args[args.index("--stats") + 1] if "--stats" in args else None
    stats = json.loads(os.environ["FAKE_SKE_STATS"])

    def write_stats(**changes):
        with open(stats_path, "w") as f:
            json.dump(dict(stats, **changes), f)

    if mode == "ok":
        print("fake ima-ske says hello", flush=True)
        write_stats()
        sys.exit(0)
    if mode == "config_error":
        print(args[-1] + ":3: error: Partition: bad name (rule: name-unique)", file=sys.stderr)
        sys.exit(2)
    if mode == "runtime_failure":
        write_stats(exit_reason="error")
        sys.exit(1)
    if mode == "wait_int":
        def stop(signum, frame):
            with open(os.environ["FAKE_SKE_LOG"] + ".signal", "w") as f:
                f.write(signal.Signals(signum).name)
            write_stats(exit_reason="signal")
            sys.exit(0)
        signal.signal(signal.SIGINT, stop)
        with open(os.environ["FAKE_SKE_LOG"] + ".ready", "w") as f:
            f.write(str(os.getpid()))
        time.sleep(20)
        sys.exit(1)
    sys.exit(99)
"""


class FakeSke:
    def __init__(self, build: Path, monkeypatch: pytest.MonkeyPatch) -> None:
        self.build = build
        self.log = build / "fake-ske-argv.json"
        self._monkeypatch = monkeypatch
        monkeypatch.setenv("FAKE_SKE_LOG", str(self.log))
        monkeypatch.setenv("FAKE_SKE_STATS", json.dumps(SAMPLE_STATS))
        self.mode = "ok"

    @property
    def mode(self) -> str:
        return self._mode

    @mode.setter
    def mode(self, value: str) -> None:
        self._mode = value
        self._monkeypatch.setenv("FAKE_SKE_MODE", value)

    def argv(self) -> list[str]:
        return json.loads(self.log.read_text())


@pytest.fixture
def fake_ske(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> FakeSke:
    """A build tree whose ske/ima-ske is a small script; IMA_BUILD_DIR points at it."""
    build = tmp_path / "build"
    binary = build / "ske" / "ima-ske"
    binary.parent.mkdir(parents=True)
    binary.write_text(f"#!{sys.executable}\n" + textwrap.dedent(_FAKE_SKE))
    binary.chmod(0o755)
    monkeypatch.setenv("IMA_BUILD_DIR", str(build))
    return FakeSke(build, monkeypatch)


@pytest.fixture
def module_xml(tmp_path: Path) -> Path:
    path = tmp_path / "m.xml"
    path.write_text("<ARINC_653_Module/>\n")
    return path


@pytest.fixture
def sample_stats() -> dict:
    """Statistics as `ima-ske --stats` writes them (a fresh copy per test)."""
    return json.loads(json.dumps(SAMPLE_STATS))
