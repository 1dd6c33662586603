# SPDX-License-Identifier: Apache-2.0
"""ima-ske's command line and start-up failures: each names what is wrong and exits with its
documented status (2 usage, invalid module or fault; 1 run-time failure), runs no frame."""

from __future__ import annotations

import json
import os
import resource
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PARTITIONS = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build")) / "partitions"
EXAMPLE = ROOT / "config" / "examples" / "three_partitions.xml"


def _ske(ske_binary: Path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, IMA_PARTITION_PATH=str(PARTITIONS))
    return subprocess.run([str(ske_binary), *args], capture_output=True, text=True, timeout=60,
                          env=env)


@pytest.mark.parametrize(("args", "says"), [
    (["--frames", "ten"], "--frames wants a non-negative integer, not 'ten'"),
    (["--frames", "-1"], "--frames wants a non-negative integer"),
    (["--node-index", "4"], "--node-index wants 0..3, not '4'"),
    (["--node-index", "x"], "--node-index wants 0..3"),
    (["--no-such-option"], "usage: ima-ske"),
    ([], "usage: ima-ske"),
    (["--check", str(EXAMPLE)], "usage: ima-ske"),  # two modules
    (["--fault", "no_such_class:fid=f1,at=0.1,partition=producer"], "ima-ske: error:"),
    (["--test-switch", "no-such-switch"], "ima-ske: error:"),
])
def test_a_bad_command_line_is_a_usage_error(ske_binary, args, says):
    module = [] if args == [] else [str(EXAMPLE)]
    p = _ske(ske_binary, *args, *module)
    assert p.returncode == 2, p.stderr
    assert says in p.stderr
    assert p.stdout == ""


def test_help_and_check(ske_binary):
    p = _ske(ske_binary, "--help")
    assert p.returncode == 0 and p.stdout.startswith("usage: ima-ske"), p
    p = _ske(ske_binary, "--check", str(EXAMPLE))
    assert p.returncode == 0, p.stderr
    assert "valid module 'three_partitions': 3 partitions" in p.stdout
    assert _ske(ske_binary, "--check", "-q", str(EXAMPLE)).stdout == ""


def test_an_unwritable_trace_stops_the_run_before_it_starts(ske_binary, tmp_path):
    trace = tmp_path / "missing" / "trace.jsonl"
    p = _ske(ske_binary, "--frames", "1", "--trace", str(trace), str(EXAMPLE))
    assert p.returncode == 1
    assert f"cannot write the trace {trace}" in p.stderr


def test_unwritable_statistics_fail_the_run(ske_binary, tmp_path):
    stats = tmp_path / "missing" / "stats.json"
    p = _ske(ske_binary, "--frames", "1", "-q", "--stats", str(stats), str(EXAMPLE))
    assert p.returncode == 1
    assert f"the statistics {stats} could not be written" in p.stderr


def test_no_bus_at_the_lockstep_socket(ske_binary, tmp_path):
    trace = tmp_path / "trace.jsonl"
    p = _ske(ske_binary, "--lockstep", str(tmp_path / "no.sock"), "--trace", str(trace),
             str(EXAMPLE))
    assert p.returncode == 1
    assert "ima-ske: error:" in p.stderr
    assert '"reason":"error"' in trace.read_text()


def test_a_program_that_cannot_be_executed_stops_the_module(ske_binary, tmp_path):
    """The exec itself fails (here: its interpreter is missing); the SKE says which partition
    and why, and starts none."""
    broken = tmp_path / "broken"
    broken.write_text("#!/nonexistent/interpreter\n")
    broken.chmod(0o755)
    module = tmp_path / "module.xml"
    module.write_text(EXAMPLE.read_text().replace('Executable="ex_monitor"',
                                                  'Executable="./broken"'))
    trace = tmp_path / "trace.jsonl"
    p = _ske(ske_binary, "--frames", "1", "--trace", str(trace), str(module))
    assert p.returncode == 1
    assert f"cannot start partition 'monitor': {broken}: No such file or directory" in p.stderr
    assert '"kind":"window_start"' not in trace.read_text()


@pytest.mark.parametrize("option", ["--trace", "--stats"])
def test_a_full_disk_under_the_trace_or_statistics_fails_the_run(ske_binary, option):
    """Recorded data that could not be written is a failed run, whatever else went right."""
    p = _ske(ske_binary, "--frames", "2", "-q", option, "/dev/full", str(EXAMPLE))
    assert p.returncode == 1
    what = "trace" if option == "--trace" else "statistics"
    assert f"the {what} /dev/full could not be written: No space left on device" in p.stderr


def test_too_few_descriptors_stop_the_start_with_one_line(ske_binary):
    """With the descriptor limit raised one by one from 4: ima-ske runs out while creating its
    port memory, then the read-only views of destination ports, then the control blocks, then
    the pipe of a partition's start; each time it stops with status 1 and one line naming what
    it could not create, before any partition runs."""
    kinds = {"port memory for": 0, "read-only port descriptor": 0, "control block": 0,
             "cannot start partition 'producer'": 0}
    for n in range(4, 40):
        def limit(n=n):
            resource.setrlimit(resource.RLIMIT_NOFILE, (n, n))

        env = dict(os.environ, IMA_PARTITION_PATH=str(PARTITIONS))
        p = subprocess.run([str(ske_binary), "--frames", "1", "-q", str(EXAMPLE)],
                           capture_output=True, text=True, timeout=60, env=env,
                           preexec_fn=limit)
        line = p.stderr.strip()
        kind = next((k for k in kinds if k in line), None)
        if kind is None:
            break  # past the parent's own descriptors
        assert p.returncode == 1 and "\n" not in line, (n, p)
        assert line.endswith("Too many open files"), line
        kinds[kind] += 1
        if kind.startswith("cannot start"):
            break
    assert all(kinds.values()), kinds


def test_the_usual_descriptor_limit_of_1024_is_enough(ske_binary):
    """Many systems start processes with at most 1024 descriptors: every partition starts and
    runs under that limit (each is handed its descriptors just above its own range)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_NOFILE, (1024, 1024))

    env = dict(os.environ, IMA_PARTITION_PATH=str(PARTITIONS))
    p = subprocess.run([str(ske_binary), "--frames", "5", "-q", "--stats", "/dev/stdout",
                        str(EXAMPLE)], capture_output=True, text=True, timeout=60, env=env,
                       preexec_fn=limit)
    assert p.returncode == 0, p.stderr
    stats = json.loads(p.stdout)
    assert stats["frames"] == 5 and stats["hm_events"] == 0, stats
