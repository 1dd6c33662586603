# SPDX-License-Identifier: Apache-2.0
"""How the oracles read a run's traces: raw lines grouped by kind and partition, the bus's
frames picked by identifier or sender, files rewritten by another tool with blanks, and lines
cut short by a killed writer."""

import json

from faultinject.traces import RunTraces, before, t_ns_of

FCS_A = 0x8B00960


def _write(path, records, blanks=False, torn=""):
    sep = (", ", ": ") if blanks else (",", ":")
    path.write_text("".join(json.dumps(r, separators=sep) + "\n" for r in records) + torn)


def _run(tmp_path, blanks=False):
    (tmp_path / "launch.json").write_text(json.dumps({"nodes": ["node1"]}))
    ske = []
    for frame in range(3):
        t = frame * 50_000_000
        for part in ("io", "nav_fcs"):
            ske.append({"t_ns": t, "node": "node1", "src": "ske", "kind": "window_start",
                        "partition": part, "window": 1, "frame": frame})
            ske.append({"t_ns": t + 5_000_000, "node": "node1", "src": "ske",
                        "kind": "window_end", "partition": part, "window": 1, "frame": frame,
                        "yielded": True, "yield_t_ns": t + 1000})
            ske.append({"t_ns": t, "node": "node1", "src": "ske", "kind": "port_hash",
                        "partition": part, "port": "OUT", "hash": f"{frame:016x}", "len": 8,
                        "seq": frame})
    ske.append({"t_ns": 60_000_000, "node": "node1", "src": "ske", "kind": "hm",
                "partition": "io", "error": "APPLICATION_ERROR"})
    _write(tmp_path / "node1.jsonl", ske, blanks, torn='{"t_ns":150000000,"node":"no')
    bus = [{"t_ns": 1000 * k, "node": "canbus", "src": "canbus", "kind": "can_tx",
            "id": FCS_A + k % 3, "ext": True, "len": 8, "data": f"0{k % 3}00000000000000",
            "from": f"node{k % 3 + 1}/io", "client": k % 3} for k in range(9)]
    bus.insert(4, {"t_ns": 3500, "node": "canbus", "src": "canbus", "kind": "can_drop",
                   "id": FCS_A, "from": "node1/io"})
    _write(tmp_path / "can.jsonl", bus, blanks, torn='{"t_ns":9000,"node":"canbus","src":"c')
    return RunTraces(tmp_path)


def test_records_by_kind_and_partition(tmp_path):
    run = _run(tmp_path)
    assert [w[:3] for w in run.windows("node1", "io")] == [
        ("window_start", 0, 0), ("window_end", 5_000_000, 0), ("window_start", 50_000_000, 1),
        ("window_end", 55_000_000, 1), ("window_start", 100_000_000, 2),
        ("window_end", 105_000_000, 2)]
    assert run.port_hash_partitions("node1") == ["io", "nav_fcs"]
    assert run.port_hashes("node1", "nav_fcs")["OUT"] == [
        (0, "0" * 16), (50_000_000, "0" * 15 + "1"), (100_000_000, "0" * 15 + "2")]
    assert [e["error"] for e in run.node_kind("node1", "hm")] == ["APPLICATION_ERROR"]
    assert run.node_kind("node1", "window_start") == []  # windows() has them
    lines = run.port_hash_lines("node1", "io")
    assert before(lines, 50_000_000) == lines[:1] and before(lines, 1 << 62) == lines


def test_frames_by_identifier_and_sender(tmp_path):
    run = _run(tmp_path)
    assert [e["t_ns"] for e in run.frames_of(FCS_A + 1)] == [1000, 4000, 7000]
    assert [e["t_ns"] for e in run.frames_from("node3/io")] == [2000, 5000, 8000]
    assert len(run.frames) == 9 and run.last_frame_t_ns() == 8000  # the torn line is no frame
    assert [e["t_ns"] for e in run.bus_kind("can_drop")] == [3500]
    assert [(t, k) for t, k, _ in run.fcs_status][:3] == [(0, 1), (1000, 2), (2000, 3)]
    assert run.fcs_field("FCS_MODE")[1][0] == [0, 3000, 6000]


def test_a_trace_rewritten_with_blanks_reads_the_same(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    compact, blank = _run(a), _run(b, blanks=True)
    assert blank.window_lines("node1", "nav_fcs") == compact.window_lines("node1", "nav_fcs")
    assert blank.frames_of(FCS_A) == compact.frames_of(FCS_A)
    assert blank.node_kind("node1", "hm") == compact.node_kind("node1", "hm")


def test_a_cut_line_sorts_last():
    assert t_ns_of(b'{"t_ns":12,"kind":"x"}') == 12
    assert t_ns_of(b'{"t_ns":') == 1 << 62
    assert t_ns_of(b'{"kind":"x","t_ns":7}') == 7


def test_the_agents_traces_end_where_the_first_agent_was_stopped(tmp_path):
    """At the end of a run the agents are stopped one by one: the later ones see the first go
    (its writers gone), which is the run's end, not a detection."""
    (tmp_path / "launch.json").write_text(json.dumps({"nodes": ["node1", "node2"]}))
    end = 20_000_000_000 - 50_000_000

    def ev(t_wall, kind, t=end, **kw):
        return {"t_wall_ns": t_wall, "t_ns": t, "node": "n", "src": "dds", "kind": kind, **kw}
    _write(tmp_path / "dds1.jsonl", [ev(1, "dds_ready", t=0),
                                     ev(5, "dds_deadline_missed", t=9_000_000_000, peer="node2"),
                                     ev(100, "dds_stop", signal=15), ev(101, "dds_exit")])
    _write(tmp_path / "dds2.jsonl", [ev(2, "dds_ready", t=0),
                                     ev(102, "dds_peer_lost", peer="node1", reason="writer_gone"),
                                     ev(110, "dds_stop", signal=15)])
    dds = RunTraces(tmp_path).dds
    assert [e["kind"] for e in dds["node1"]] == ["dds_ready", "dds_deadline_missed"]
    assert [e["kind"] for e in dds["node2"]] == ["dds_ready"]


def test_the_agents_traces_end_where_the_nodes_stopped(tmp_path):
    """Between the nodes' end (their io links close in the last frame) and the agents' stop,
    a loaded host may let the agents idle past their liveliness lease: what they see then is
    the run ending. A node lost before the last frame is kept."""
    (tmp_path / "launch.json").write_text(json.dumps({"nodes": ["node1", "node2"]}))
    end = 20_000_000_000 - 50_000_000

    def ev(t_wall, kind, t=end, **kw):
        return {"t_wall_ns": t_wall, "t_ns": t, "node": "n", "src": "dds", "kind": kind, **kw}
    _write(tmp_path / "dds1.jsonl", [ev(1, "dds_ready", t=0),
                                     ev(3, "io_disconnect", t=5_000_000_000, reason="closed"),
                                     ev(4, "dds_peer_lost", t=5_000_000_000, peer="node2",
                                        reason="liveliness"),
                                     ev(50, "io_disconnect", reason="closed"),
                                     ev(1500, "dds_peer_lost", peer="node2", reason="liveliness"),
                                     ev(1510, "dds_stop", signal=15)])
    _write(tmp_path / "dds2.jsonl", [ev(2, "dds_ready", t=0),
                                     ev(60, "io_disconnect", reason="closed"),
                                     ev(1501, "dds_peer_lost", peer="node1", reason="liveliness"),
                                     ev(1520, "dds_stop", signal=15)])
    dds = RunTraces(tmp_path).dds
    assert [e["kind"] for e in dds["node1"]] == ["dds_ready", "io_disconnect", "dds_peer_lost"]
    assert [e["kind"] for e in dds["node2"]] == ["dds_ready"]
