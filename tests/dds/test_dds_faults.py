# SPDX-License-Identifier: Apache-2.0
"""ima-dds-node --fault: a node's agent that withholds (dds_drop) or delays (dds_delay) its
node's inputs and health for a spell of frames, in emulated time; the other agents go on
without that node's inputs for exactly those frames, in every run alike."""

from __future__ import annotations

import time

import pytest
from dds_helpers import exchange_round, inputs_for

from ima.dds import xch
from ima.dds.agent import start_agent

ALL = 0b111
FRAME_NS = 50_000_000


@pytest.fixture
def faulty_agents(agent_bin, run_dir, domain):
    """faulty_agents({2: [spec, ...]}) -> three ready agents, the given ones with --fault."""
    started = []

    def start(faults: dict[int, list[str]]):
        for k in (1, 2, 3):
            extra = [w for spec in faults.get(k, []) for w in ("--fault", spec)]
            started.append(start_agent(k, 3, run_dir, domain, extra=extra))
        for a in started:
            a.wait_ready()
        return started

    yield start
    for a in started:
        a.stop()


def run_frames(clients, frames: int):
    """Every node's io, frame by frame: its inputs and its health; returns each node's AGREED."""
    got = {}
    for frame in range(frames):
        got[frame] = exchange_round(clients, frame, {1: ALL, 2: ALL, 3: ALL})
        for node, c in clients.items():
            c.send(xch.HEALTH, frame, frame * FRAME_NS, xch.pack_health(membership=ALL))
    return got


def test_dropped_inputs_are_missing_at_the_others_for_the_spell_only(faulty_agents, connect):
    ags = faulty_agents({2: ["dds_drop:fid=d1,at=250ms,until=500ms"]})
    clients = {a.node: connect(a) for a in ags}
    got = run_frames(clients, 14)
    spell = range(5, 10)  # frames starting in [250 ms, 500 ms)
    for frame, agreed in got.items():
        for node in (1, 3):
            want = 0b101 if frame in spell else ALL
            assert agreed[node].present == want, (frame, node, agreed[node].present)
            if frame not in spell:
                assert agreed[node].of(2) == inputs_for(2, frame, ALL)
        # node 2's own io is not faulty: it agrees with what it has, its own inputs included
        assert agreed[2].present == ALL
    t_stop = time.time_ns()
    for a in ags:
        a.stop()
    faulty, others = ags[1], (ags[0], ags[2])
    events = faulty.of_kind("fault")
    assert [(e["state"], e["t_ns"], e["frame"]) for e in events] == [
        ("applied", 250_000_000, 5), ("cleared", 500_000_000, 10)], events
    assert all(e["fid"] == "d1" and e["class"] == "dds_drop" and e["target"] == "node2/dds"
               for e in events)
    st = faulty.read_stats()
    assert st["withheld"] == 2 * len(spell) and st["published_late"] == 0
    assert st["faults"] == [{"fid": "d1", "class": "dds_drop", "frames": len(spell)}]
    # every inputs sample went out: the withheld ones as marks that they are lost
    assert st["topics"]["rpas_CrossChannelInputs"]["written"] == 14
    assert st["topics"]["rpas_NodeHealth"]["written"] == 14 - len(spell)
    for a in others:
        s = a.read_stats()
        assert s["lost_marks"] == len(spell) and s["partial"] == len(spell), s
        assert s["timeouts"] == 0 and s["faults"] == []
        assert not a.of_kind("fault")
        # each frame received as lost is traced, with its emulated time
        missing = [(e["peer"], e["frame"], e["t_ns"]) for e in a.of_kind("xch_peer_missing")]
        assert missing == [("node2", f, f * FRAME_NS) for f in spell], missing
        # node 2 is not taken for lost or hung: the frames are lost, the node is not
        assert not [e for e in a.of_kind("dds_peer_lost") if e["t_wall_ns"] < t_stop]


def test_delayed_inputs_come_too_late_and_are_stale(faulty_agents, connect):
    ags = faulty_agents({2: ["dds_delay:fid=l1,at=100ms,period=400ms,on=100ms,until=900ms,frames=3"]})
    clients = {a.node: connect(a) for a in ags}
    got = run_frames(clients, 20)
    spells = {2, 3, 10, 11}  # frames starting in [100, 200) and [500, 600) ms
    for frame, agreed in got.items():
        for node in (1, 3):
            assert agreed[node].present == (0b101 if frame in spells else ALL), (frame, node)
    for a in ags:
        a.stop()
    events = ags[1].of_kind("fault")
    assert [(e["state"], e["frame"]) for e in events] == [
        ("applied", 2), ("cleared", 4), ("applied", 10), ("cleared", 12)], events
    st = ags[1].read_stats()
    assert st["published_late"] == 2 * len(spells) and st["withheld"] == 0
    for a in (ags[0], ags[2]):
        s = a.read_stats()
        # the late samples arrived after their frame was answered: stale, ignored
        assert s["lost_marks"] == len(spells) and s["stale"] >= len(spells), s


def test_bad_fault_specs_are_refused(agent_bin, run_dir, domain):
    for spec, says in (("dds_delay:fid=x,at=1s", "frames=N"),
                       ("can_drop:fid=x,at=1s", "dds_drop and dds_delay"),
                       ("dds_drop:at=1s", "fid=ID is required")):
        a = start_agent(1, 2, run_dir, domain, extra=["--fault", spec])
        assert a.proc.wait(timeout=10) == 2
        assert says in a.stderr_text(), a.stderr_text()
