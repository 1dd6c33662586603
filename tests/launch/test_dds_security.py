# SPDX-License-Identifier: Apache-2.0
"""DDS Security against forged participants. A hostile participant (ima-dds-forge) reads the
nodes' cross-channel inputs and publishes, ahead of node2 and node3, forged copies keyed as
theirs: 300 ft higher, stamped newer than any real sample. With security on, whether it holds
no credentials or node1's (a stolen key), the flight is bit-identical to the clean run and
the summary lists it in `refused`. With security off the same attack changes the flight,
which shows that the test really attacks; a far-future time stamp is refused by io's
agreement even then."""

from __future__ import annotations

import json
import stat
import subprocess
import threading
import time
from pathlib import Path

import pytest
from flight_helpers import fly_unless_host_stalled
from launch_helpers import TRIPLEX, Run

from ima import dds, paths
from ima.dds import security
from ima.launch import options as launch_options
from ima.launch import run as launch_run
from ima.launch import summary as launch_summary

SEED = 5
DURATION_S = 60.0
FORGED = "2,3"


def _forge_binary() -> Path:
    return paths.build_dir() / "nodes" / "dds" / "ima-dds-forge"


class Forger:
    """Starts ima-dds-forge on the run's domain as soon as the launcher has written
    launch.json (before the agents' discovery ends), and stops it when asked."""

    def __init__(self, run_dir: Path, *args: str, identity: str | None = None) -> None:
        self.run_dir, self.args, self.identity = run_dir, list(args), identity
        self.proc: subprocess.Popen | None = None
        self.error: str | None = None
        self._thread = threading.Thread(target=self._start, daemon=True)
        self._thread.start()

    def _start(self) -> None:
        launch_json = self.run_dir / "launch.json"
        end = time.monotonic() + 60
        while True:  # it may be there half-written
            try:
                info = json.loads(launch_json.read_text())
                break
            except (OSError, ValueError):
                if time.monotonic() > end:
                    self.error = "no launch.json"
                    return
                time.sleep(0.01)
        cmd = [str(_forge_binary()), "--domain", str(info["dds_domain"]), "--nodes", "3",
               "--as", FORGED, "--seconds", "120", *self.args]
        if self.identity:
            cmd += ["--security", info["dds_security"], "--identity", self.identity]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, env=dds.dds_env())

    def stop(self) -> dict:
        """Its report: {"seen": samples read, "writers": [{"as", "partition", "written"}]}."""
        self._thread.join(60)
        assert self.error is None and self.proc is not None, self.error
        self.proc.terminate()
        out, err = self.proc.communicate(timeout=30)
        lines = [ln for ln in out.splitlines() if ln.startswith("{")]
        assert lines, f"ima-dds-forge said nothing: {err}"
        self.stderr = err
        return json.loads(lines[-1])


def _attacked(launches, name: str, mode: str, *args: str, identity: str | None = None):
    """A run with the forger at work (a fresh one if the run is flown again), summarised."""
    run_dir = launches.base / name
    opts = launch_options.LaunchOptions(system=TRIPLEX, run_dir=run_dir, duration_s=DURATION_S,
                                        seed=SEED, dds_security=mode)
    reports = []

    def fly():
        forger = Forger(run_dir, *args, identity=identity)
        try:
            return launch_run.launch(opts)
        finally:
            reports.append(forger.stop())

    result = fly_unless_host_stalled(fly, run_dir, name)
    summary = launch_summary.summarise(run_dir, launch_options.default_pilot(), DURATION_S,
                                       result.nodes, result.killed, result.wall_s)
    return Run(run_dir, summary, result), reports[-1]


def _losses(trace: Path) -> tuple[set[str], set[str]]:
    """(peers an agent's trace says were lost while their node still flew, peers whose node
    ended first). At the run's end each node's io hangs up (`xch_peer_withdrawn` at the
    others), then the launcher stops the agents, each with its SIGTERM before any runs on: one
    that sees another leave traces `dds_peer_left`. Between the two, on a loaded host, an
    agent may still lose a peer to its liveliness lease: the run ending, not a loss."""
    ended, lost = set(), set()
    for line in trace.read_text().splitlines():
        e = json.loads(line)
        if e["kind"] == "xch_peer_withdrawn":
            ended.add(e["peer"])
        elif e["kind"] == "dds_peer_lost" and e["peer"] not in ended:
            lost.add(e["peer"])
    return lost, ended


def _truth(run) -> bytes:
    return (run.run_dir / "truth.jsonl").read_bytes()


@pytest.fixture(scope="module")
def clean(launches):
    return launches.launch("clean-secure", duration_s=DURATION_S, seed=SEED)


def test_the_run_has_its_own_authorities_and_private_keys(clean):
    d = clean.run_dir / security.DIR_NAME
    assert stat.S_IMODE(d.stat().st_mode) == 0o700
    names = sorted(p.name for p in d.iterdir())
    assert names == sorted(["governance.p7s", "identity_ca.pem", "permissions.p7s",
                            "permissions_ca.pem", *(f"node{k}.{e}" for k in (1, 2, 3)
                                                    for e in ("key", "pem"))])
    for k in (1, 2, 3):
        assert stat.S_IMODE((d / f"node{k}.key").stat().st_mode) == 0o600
    # the CAs' keys are gone: nobody can issue another identity for the run
    assert not list(d.glob("*_ca.key"))
    verify = subprocess.run(["openssl", "verify", "-CAfile", str(d / "identity_ca.pem"),
                             *(str(d / f"node{k}.pem") for k in (1, 2, 3))],
                            capture_output=True, text=True)
    assert verify.returncode == 0, verify.stderr
    signed = subprocess.run(["openssl", "smime", "-verify", "-in", str(d / "permissions.p7s"),
                             "-CAfile", str(d / "permissions_ca.pem")],
                            capture_output=True, text=True)
    assert signed.returncode == 0, signed.stderr
    # node K may publish only in its own partition
    grant1 = signed.stdout.split('<grant name="node1">')[1].split("</grant>")[0]
    assert "<publish><topics>" in grant1
    assert grant1.split("<publish>")[1].split("</publish>")[0].count("<partition>") == 1
    assert "<partition>node1</partition></partitions></publish>" in grant1
    assert security.mode_of(d) == "sign"
    assert clean.summary["dds_security"] == "sign"
    assert clean.summary["refused"] == []
    for k in (1, 2, 3):
        st = json.loads((clean.run_dir / f"dds{k}.json").read_text())
        assert st["security"] is True and st["refused_samples"] == 0
        assert st["foreign_participants"] == []
        # the plugin's session keys come from the agent's HMAC(): derived once per peer and
        # session, then reused for each message (nodes/README.md)
        keys = st["session_keys"]
        assert keys["reused"] > 10 * keys["derived"] > 0, keys
        # and the AES-GCM implementation from its cipher initialisations: fetched once, not
        # at each message; no other cipher is asked for
        inits = st["cipher_inits"]
        assert inits["prefetched"] > keys["reused"] and inits["as_given"] == 0, inits


def test_an_unauthenticated_participant_changes_nothing(launches, clean):
    run, forge = _attacked(launches, "forged-anonymous", "sign")
    assert forge["seen"] == 0  # it could not even read: nothing was sent to it
    assert _truth(run) == _truth(clean)
    refused = [r for r in run.summary["refused"] if r["what"] == "dds_participant"]
    assert len(refused) == 1, run.summary["refused"]
    assert "ima-dds-forge" in refused[0]["detail"], refused


def test_a_stolen_node_key_cannot_speak_for_another_node(launches, clean):
    run, forge = _attacked(launches, "forged-node1", "sign", identity="node1")
    # its permissions refused it node2's and node3's partitions: it wrote in its own
    assert {w["partition"] for w in forge["writers"]} == {"node1"}, forge
    assert all(w["written"] > 100 for w in forge["writers"]), forge
    assert _truth(run) == _truth(clean)
    refused = [r for r in run.summary["refused"] if r["what"] == "dds_participant"]
    assert len(refused) == 1, run.summary["refused"]
    detail = refused[0]["detail"]
    assert "keyed as node2 from partition 'node1' were refused" in detail, detail
    assert "keyed as node3 from partition 'node1' were refused" in detail, detail
    for k in (1, 2, 3):
        st = json.loads((run.run_dir / f"dds{k}.json").read_text())
        assert st["refused_samples"] > 100, st["refused"]
        # the intruder leaving or its writers coming and going lost no node while it flew
        lost, ended = _losses(run.run_dir / f"dds{k}.jsonl")
        assert not lost, lost
        assert all(not p["dead"] or f"node{p['node']}" in ended for p in st["peers"]), \
            (st["peers"], ended)
    assert run.summary["vote_status"] == clean.summary["vote_status"]


def test_without_security_the_same_attack_changes_the_flight(launches, clean):
    run, forge = _attacked(launches, "forged-insecure", "off")
    assert forge["seen"] > 100 and all(w["written"] > 100 for w in forge["writers"]), forge
    assert run.summary["dds_security"] == "off"
    assert _truth(run) != _truth(clean)


def test_far_future_stamps_are_left_out_of_the_agreement(launches, clean):
    run, forge = _attacked(launches, "forged-future", "off", "--future")
    assert forge["seen"] > 100, forge
    assert _truth(run) == _truth(clean)
    said = [r["text"] for r in run.records("node1.jsonl", "app_message")
            if r.get("text", "").startswith("cross-channel agreement:")]
    assert said, "io did not say it left samples out"
    assert all(("node2" in t or "node3" in t) and "node1" not in t for t in said), said
