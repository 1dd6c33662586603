# SPDX-License-Identifier: Apache-2.0
"""RUN_DIR/run.mcap: every record of every producer is in it (by its number), it is read back
by the `mcap` package's indexed reader, and `ima trace recover` makes a readable one from a
run killed outright (kill -9 of every process) at random moments, losing at most the last
second of emulated time."""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import time
from collections import defaultdict
from pathlib import Path

import pytest
from mcap.reader import make_reader

ROOT = Path(__file__).resolve().parents[2]
IMA = str(ROOT / "ima")
TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"


def _messages(path: Path) -> dict[str, list]:
    out = defaultdict(list)
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes  # indexed
        for _, ch, m in reader.iter_messages():
            out[ch.topic].append(m)
    return out


def _lines(path: Path) -> int:
    with open(path, "rb") as f:
        return sum(1 for _ in f)


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    run = tmp_path_factory.mktemp("rec") / "run"
    p = subprocess.run([IMA, "launch", str(TRIPLEX), "--duration", "10", "--run-dir", str(run),
                        "--json"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    return run, json.loads(p.stdout)


def test_the_recording_holds_every_record_of_every_producer(recorded):
    run, summary = recorded
    assert summary["recording"] == str(run / "run.mcap") and "recording_error" not in summary
    msgs = _messages(run / "run.mcap")
    assert summary["recording_messages"] == sum(len(v) for v in msgs.values())

    def seqs(*topics):
        return sorted(m.sequence for t in topics for m in msgs[t])
    # each producer's records, by their number (line) in its trace: none missing, none twice
    assert seqs("/can/frames", "/can/events") == list(range(_lines(run / "can.jsonl")))
    for k in (1, 2, 3):
        node = f"node{k}"
        assert seqs(f"/{node}/schedule", f"/{node}/hm", f"/{node}/events") == list(
            range(_lines(run / f"{node}.jsonl")))
        assert seqs(f"/{node}/dds") == list(range(_lines(run / f"dds{k}.jsonl")))
        assert msgs[f"/{node}/fdr"], node
    assert seqs("/world/events", "/vote") == list(range(_lines(run / "world.jsonl")))
    assert seqs("/world/truth") == list(range(_lines(run / "truth.jsonl")))
    # the frames' decoded identifier and the signals' channels
    f = json.loads(msgs["/can/frames"][0].data)
    assert {"t_ns", "id", "data", "from", "lcc", "fid", "doc", "rci", "name"} <= set(f)
    act = json.loads(msgs["/can/signals/ACT_CMD_A"][0].data)
    assert {"ELEV_CMD_A", "THR_CMD_A", "t_ns", "from"} <= set(act)
    fix = json.loads(msgs["/world/location"][-1].data)
    assert fix["latitude"] > 0 and fix["timestamp"]["sec"] >= 9
    pose = json.loads(msgs["/world/pose"][-1].data)
    q = pose["pose"]["orientation"]
    assert abs(sum(v * v for v in q.values()) - 1) < 1e-9
    with open(run / "run.mcap", "rb") as fh:
        meta = {m.name: m.metadata for m in make_reader(fh).iter_metadata()}
    assert json.loads(meta["ima.run"]["seed"]) == 1 and "commit" in meta["ima.run"]["provenance"]


def test_ima_trace_reads_the_recording(recorded):
    run, _ = recorded
    p = subprocess.run([IMA, "trace", "stats", str(run / "run.mcap"), "--json"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["frames"] == sum(
        1 for line in open(run / "can.jsonl") if '"kind":"can_tx"' in line)


def _run_pids(run_dir: Path) -> list[int]:
    pids = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            cmd = (d / "cmdline").read_bytes()
        except OSError:
            continue
        if str(run_dir).encode() in cmd:
            pids.append(int(d.name))
    return pids


def _last_t(msgs, topic) -> int:
    return max((m.log_time for m in msgs[topic]), default=0)


@pytest.mark.parametrize("attempt", range(3))
def test_a_run_killed_outright_is_recovered(tmp_path, attempt):
    rng = random.Random(attempt * 7919 + os.getpid())
    run = tmp_path / "killed"
    proc = subprocess.Popen([IMA, "launch", str(TRIPLEX), "--duration", "600", "--run-dir",
                             str(run), "--json"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        end = time.monotonic() + 60
        while not (run / "truth.jsonl").exists() and time.monotonic() < end:
            time.sleep(0.05)
        time.sleep(rng.uniform(1.0, 4.0))
        for pid in _run_pids(run) + [proc.pid]:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
    finally:
        proc.wait(timeout=30)
        time.sleep(0.5)
        for pid in _run_pids(run):  # anything that started meanwhile
            os.kill(pid, signal.SIGKILL)
    p = subprocess.run([IMA, "trace", "recover", str(run), "--json"], capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    msgs = _messages(run / "run.mcap")
    t_kill = _last_t(msgs, "/can/frames")
    assert t_kill > 1_000_000_000, "the run was killed before it flew"
    for topic in ("/world/truth", "/node1/schedule", "/node2/schedule", "/node3/schedule"):
        lost = t_kill - _last_t(msgs, topic)
        assert lost <= 1_000_000_000, (topic, lost / 1e9)


def test_the_fast_reader_reads_what_the_mcap_package_reads(recorded):
    from ima.recording import mcapread

    run, _ = recorded
    topics = ["/can/frames", "/world/truth", "/node2/hm", "/vote"]
    ours = [(t, time_, data) for t, time_, data in mcapread.messages(run / "run.mcap", topics)]
    with open(run / "run.mcap", "rb") as f:
        theirs = [(ch.topic, m.log_time, m.data) for _, ch, m in
                  make_reader(f).iter_messages(topics=topics, log_time_order=False)]
    assert sorted(ours) == sorted(theirs) and len(ours) > 1000


def test_the_c_path_records_a_flight_as_the_python_does(recorded, tmp_path, monkeypatch):
    """Of a flight's traces the C path and the Python alone make the same file, byte for byte;
    the launcher's recording (made with the C path while the run flew, so in another order)
    holds the same messages."""
    from ima.recording import fast, write

    run, _ = recorded
    assert fast.library() is not None
    write.record(run, output=tmp_path / "c.mcap")
    monkeypatch.setattr(fast, "_lib", None)
    write.record(run, output=tmp_path / "python.mcap")
    assert (tmp_path / "python.mcap").read_bytes() == (tmp_path / "c.mcap").read_bytes()

    def messages(path):
        with open(path, "rb") as f:
            return sorted((ch.topic, m.log_time, m.sequence, m.data)
                          for _, ch, m in make_reader(f).iter_messages(log_time_order=False))
    launched = messages(run / "run.mcap")
    assert launched == messages(tmp_path / "python.mcap") and len(launched) > 10000


def test_no_recording_leaves_the_traces_for_recover(tmp_path):
    run = tmp_path / "run"
    p = subprocess.run([IMA, "fly", "--duration", "5", "--run-dir", str(run), "--json",
                        "--no-recording"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    assert "recording" not in json.loads(p.stdout) and not (run / "run.mcap").exists()
    p = subprocess.run([IMA, "trace", "recover", str(run)], capture_output=True, text=True)
    assert p.returncode == 0 and "run.mcap" in p.stdout, p.stderr
    msgs = _messages(run / "run.mcap")
    assert len(msgs["/world/truth"]) == _lines(run / "truth.jsonl")
    assert "/node1/schedule" in msgs and "/node1/dds" not in msgs  # one node: no agent
