# SPDX-License-Identifier: Apache-2.0
"""ima-dds-node: the cross-channel exchange between real agents over real (loopback) DDS."""

from __future__ import annotations

import socket
import time

import pytest
from dds_helpers import exchange_round, inputs_for

from ima.dds import xch
from ima.dds.xch import XchClient

ALL = 0b111


def test_agreed_holds_every_nodes_inputs(agents, connect):
    ags = agents(3)
    clients = {a.node: connect(a) for a in ags}
    assert all(c.nodes == 3 for c in clients.values())
    for frame in range(20):
        got = exchange_round(clients, frame, {1: ALL, 2: ALL, 3: ALL})
        for node, agreed in got.items():
            assert agreed.frame == frame and agreed.t_ns == frame * 50_000_000
            assert agreed.present == ALL, f"node{node} frame {frame}"
            for k in (1, 2, 3):
                assert agreed.of(k) == inputs_for(k, frame, ALL)
        assert got[1] == got[2] == got[3]
    for a in ags:
        a.stop()
        st = a.read_stats()
        assert st["agreed_frames"] == 20 and st["partial"] == 0 and st["timeouts"] == 0
        assert st["topics"]["rpas_CrossChannelInputs"]["written"] == 20
        assert st["topics"]["rpas_CrossChannelInputs"]["read"] >= 40
        assert st["exchange_latency_us"]["count"] == 20
        # every peer sample taken after discovery: 2 peers x 20 frames, one-way DDS latency
        lat = st["dds_latency_us"]
        assert lat["count"] == 40
        assert 0 < lat["min"] <= lat["median"] <= lat["p95"] <= lat["max"] < 1e6
        ready = a.of_kind("dds_ready")
        assert ready and len(ready[0]["discovered"]) == 2 and ready[0]["missing"] == []


def test_wait_mask_is_honoured(agents, connect):
    ags = agents(3)
    c1, c2, c3 = (connect(a) for a in ags)
    # node 3 publishes frame 0 but nodes 1 and 2 do not wait for it: it is left out, so that
    # the content never depends on whether it happened to arrive in time.
    c3.send_inputs(0, 0, inputs_for(3, 0, ALL))
    got = exchange_round({1: c1, 2: c2}, 0, {1: 0b011, 2: 0b011})
    assert got[1].present == got[2].present == 0b011
    assert c3.await_agreed(0).present == ALL

    # node 1 waits for node 3, which has not published frame 1: no answer until it does
    c1.send_inputs(1, 50_000_000, inputs_for(1, 1, ALL))
    c2.send_inputs(1, 50_000_000, inputs_for(2, 1, 0b011))
    assert c2.await_agreed(1).present == 0b011  # node 2 does not wait for node 3
    with pytest.raises(TimeoutError):
        c1.await_agreed(1, timeout=0.5)
    c3.send_inputs(1, 50_000_000, inputs_for(3, 1, ALL))
    a1 = c1.await_agreed(1)
    assert a1.present == ALL and a1.of(3) == inputs_for(3, 1, ALL)
    assert c3.await_agreed(1).present == ALL

    # a node never waits for itself
    c1.send_inputs(2, 100_000_000, inputs_for(1, 2, 0b001))
    assert c1.await_agreed(2, timeout=2).present == 0b001


def test_killed_agent_is_not_waited_for_after_its_lease(agents, connect):
    ags = agents(3, extra=["--lease-ms", "1000"])
    clients = {a.node: connect(a) for a in ags}
    for frame in range(3):
        exchange_round(clients, frame, {1: ALL, 2: ALL, 3: ALL})
    ags[2].kill()  # SIGKILL: no goodbye on DDS
    t_kill = time.time_ns()
    clients[3].close()
    del clients[3]
    t0 = time.monotonic()
    got = exchange_round(clients, 3, {1: ALL, 2: ALL}, timeout=10)
    waited = time.monotonic() - t0
    assert got[1].present == got[2].present == 0b011
    assert got[1] == got[2]
    assert waited < 5, f"waited {waited:.1f} s for a dead node (lease 1 s)"
    for a in ags[:2]:
        lost = a.of_kind("dds_peer_lost", peer="node3")
        assert len(lost) == 1, a.events()
        assert lost[0]["reason"] in ("liveliness", "no_writers", "unmatched", "writer_gone")
        assert t_kill < lost[0]["t_wall_ns"] < t_kill + 5 * 10**9
    # dead for the rest of the run: later frames do not wait either
    got = exchange_round(clients, 4, {1: ALL, 2: ALL}, timeout=2)
    assert got[1].present == 0b011


def run_scenario(agents_fn, connect) -> list[tuple[int, int, int, bytes]]:
    """A fixed input sequence with silences, narrowed masks and an io reconnection; returns
    every AGREED each node received, as (node, frame, present, raw inputs)."""
    ags = agents_fn(3)
    clients = {a.node: connect(a) for a in ags}
    seen = []

    def record(got):
        for node, a in sorted(got.items()):
            raw = b"".join(i.pack() for i in a.inputs)
            seen.append((node, a.frame, a.present, raw))

    for frame in range(30):
        masks = {1: ALL, 2: ALL, 3: ALL}
        active = dict(clients)
        if 5 <= frame < 8:  # node 3's io is silent and the others know it (membership)
            del active[3]
            masks = {1: 0b011, 2: 0b011}
        if frame == 12:
            masks[1] = 0b101  # node 1 does not count on node 2 this frame
        if frame == 20:
            # node 3's io dies; the others still count on it this frame (their membership
            # has not caught up): they stop waiting when its agent withdraws its inputs
            clients[3].close()
            del active[3]
            masks = {1: ALL, 2: ALL}
        if 20 < frame < 23:
            del active[3]
            masks = {1: 0b011, 2: 0b011} if frame == 22 else {1: ALL, 2: ALL}
        if frame == 23:
            # node 3's io is back: its first frame counts for nobody else (whether it arrived
            # before their request is timing), it is waited for again from frame 24
            clients[3] = connect(ags[2])
            active[3] = clients[3]
        record(exchange_round(active, frame, {k: masks.get(k, ALL) for k in active}))
        if frame == 23:
            time.sleep(0.05)  # see test_io_reconnects_after_a_restart
    return seen


def test_same_inputs_give_the_same_agreed_sequence(agents_factory_pair, connect):
    first = run_scenario(agents_factory_pair[0], connect)
    second = run_scenario(agents_factory_pair[1], connect)
    assert len(first) == len(second) == 30 * 3 - 3 - 3  # node 3 silent in 5..7 and 20..22
    assert first == second
    # the scenario did exercise the rules it is about
    presents = {(n, f): p for n, f, p, _ in first}
    assert presents[(1, 6)] == 0b011 and presents[(1, 12)] == 0b101
    assert presents[(1, 20)] == 0b011 and presents[(1, 23)] == 0b011
    assert presents[(3, 23)] == ALL and presents[(1, 24)] == ALL


@pytest.fixture
def agents_factory_pair(agent_bin, run_dir):
    """Two independent runs: each its own domain and run folder."""
    from ima import dds
    from ima.dds.agent import start_agents

    started, domains = [], []

    def factory(i):
        def start(nodes=3, **kw):
            d = dds.domain_for_run()
            domains.append(d)
            sub = run_dir / f"run{i}"
            sub.mkdir()
            got = start_agents(nodes, sub, d, **kw)
            started.extend(got)
            return got
        return start

    yield factory(0), factory(1)
    for a in started:
        a.stop()
    for d in domains:
        dds.release_domain(d)


def test_bad_datagrams_are_counted_and_survived(agents, connect):
    ags = agents(2)
    a1 = ags[0]
    c2 = connect(ags[1])
    raw = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    raw.connect(str(a1.socket))
    inputs = inputs_for(1, 0, 0b11).pack()
    bad = [
        b"\x00" * 10,  # short
        xch.HDR.pack(0xDEADBEEF, 1, xch.INPUTS, 1, 0, 0) + inputs,  # magic
        xch.HDR.pack(xch.MAGIC, 9, xch.INPUTS, 1, 0, 0) + inputs,  # version
        xch.pack_hdr(xch.INPUTS, 1) + inputs,  # before HELLO
    ]
    for b in bad:
        raw.send(b)
    raw.send(xch.pack_hdr(xch.HELLO, 1))
    assert len(raw.recv(4096)) == xch.HDR.size  # WELCOME
    bad = [
        xch.pack_hdr(xch.AGREED, 1) + b"\x00" * xch.AGREED_SIZE,  # agent-only type
        xch.pack_hdr(42, 1),  # unknown type
        xch.pack_hdr(xch.INPUTS, 2) + inputs,  # another node's
        xch.pack_hdr(xch.INPUTS, 1) + inputs[:-1],  # short payload
        xch.pack_hdr(xch.HEALTH, 1) + xch.pack_health() + b"\x00",  # long payload
        xch.pack_hdr(xch.HELLO, 1),  # second HELLO
        b"\xff" * 5000,  # longer than any datagram
    ]
    for b in bad:
        raw.send(b)
    # still serving: a good exchange
    raw.send(xch.pack_hdr(xch.INPUTS, 1, 0, 0) + inputs)
    c2.send_inputs(0, 0, inputs_for(2, 0, 0b11))
    raw.settimeout(10)
    agreed = xch.unpack_agreed(raw.recv(4096))
    assert agreed.present == 0b11 and c2.await_agreed(0).present == 0b11
    raw.close()
    assert a1.proc.poll() is None
    a1.stop()
    assert a1.read_stats()["bad_datagrams"] == 11
    reasons = [e["reason"] for e in a1.of_kind("bad_datagram")]
    assert reasons == ["short", "magic", "version", "no_hello", "type", "type", "node", "size",
                       "size", "hello_again", "too_long"]


def test_hello_of_another_node_is_refused(agents):
    ags = agents(1)
    with pytest.raises(ConnectionError):
        XchClient(str(ags[0].socket), 2, timeout=5)
    c = XchClient(str(ags[0].socket), 1, timeout=5)  # the agent is still there
    assert c.exchange(0, 0, inputs_for(1, 0, 0b1), timeout=2).present == 0b1
    c.close()


def test_io_reconnects_after_a_restart(agents, connect):
    ags = agents(2)
    c1, c2 = connect(ags[0]), connect(ags[1])
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    c1.close()  # node 1's io partition dies
    time.sleep(0.2)
    c1 = connect(ags[0])
    got = exchange_round({1: c1, 2: c2}, 1, {1: 0b11, 2: 0b11})
    assert got[1].present == 0b11
    assert got[2].present == 0b10  # node 1's first frame back counts for nobody else
    # From the next frame on it counts again, provided its first sample reached the other
    # agents by then: a frame of lockstep later in a run, here a pause.
    time.sleep(0.05)
    got = exchange_round({1: c1, 2: c2}, 2, {1: 0b11, 2: 0b11})
    assert got[1].present == got[2].present == 0b11
    ags[0].stop()
    kinds = [e["kind"] for e in ags[0].events()]
    assert kinds.count("io_connect") == kinds.count("io_hello") == 2
    assert kinds.count("io_disconnect") == 1
    assert ags[0].read_stats()["io_connections"] == 2
    # while node 1's io was away its inputs instance was withdrawn: node 2 saw it go
    assert ags[1].of_kind("xch_peer_withdrawn", peer="node1")


def timed_exchange(client, frame: int, timeout: float) -> tuple:
    """(AGREED, seconds waited) of node 1's frame, awaiting nodes 1 and 2."""
    t0 = time.monotonic()
    got = client.exchange(frame, frame * 50_000_000, inputs_for(1, frame, 0b11), timeout=timeout)
    return got, time.monotonic() - t0


def test_realtime_waits_at_most_the_timeout(agents, connect):
    ags = agents(2, realtime=True, extra=["--xch-timeout-us", "20000"])
    c1, c2 = connect(ags[0]), connect(ags[1])
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    got, waited = timed_exchange(c1, 1, timeout=5)
    assert got.present == 0b01
    assert 0.019 <= waited < 1.0
    ags[0].stop()
    # (frame 0 may time out too on a loaded machine: real time is real)
    (ev,) = ags[0].of_kind("xch_timeout", frame=1)
    assert ev["missing"] == ["node2"] and ev["waited_us"] >= 20000
    assert ags[0].read_stats()["timeouts"] >= 1


def test_health_deadline_miss_is_traced_while_this_node_flies(agents, connect):
    """Emulated time: node 1's health stops while node 2's io waits for a frame's agreement
    (node 1's inputs never come): a miss of node 1, traced once per episode."""
    ags = agents(2, extra=["--deadline-ms", "100", "--lease-ms", "60000"])
    c1, c2 = connect(ags[0]), connect(ags[1])
    for c in (c1, c2):
        c.send(xch.HEALTH, 0, 0, xch.pack_health(membership=0b11))
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    c2.send_inputs(1, 50_000_000, inputs_for(2, 1, 0b11))  # waits for node 1's frame 1
    time.sleep(0.6)  # no more health from node 1
    c1.send(xch.HEALTH, 12, 0, xch.pack_health(membership=0b11))
    time.sleep(0.1)
    c1.send_inputs(1, 50_000_000, inputs_for(1, 1, 0b11))
    c2.await_agreed(1, 10)
    c2.send_inputs(2, 100_000_000, inputs_for(2, 2, 0b11))
    time.sleep(0.6)
    ags[1].stop()
    misses = ags[1].of_kind("dds_deadline_missed", peer="node1")
    assert len(misses) == 2, misses  # one per episode, not one per period
    assert ags[1].read_stats()["peers"][0]["deadline_misses"] >= 4


def test_health_deadline_is_no_miss_while_the_run_is_paused(agents, connect):
    """Emulated time: no io asks for a frame (the bus stopped at the end of the run, or the
    host stalled everything): the wall-clock deadline says nothing of the peer."""
    # a deadline the exchange itself cannot outlast on a loaded host (while io waits for the
    # agreement, a miss is one), then a pause of three deadlines
    ags = agents(2, extra=["--deadline-ms", "250"])
    c1, c2 = connect(ags[0]), connect(ags[1])
    for c in (c1, c2):
        c.send(xch.HEALTH, 0, 0, xch.pack_health(membership=0b11))
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    time.sleep(0.8)
    ags[1].stop()
    assert not ags[1].of_kind("dds_deadline_missed")
    st = ags[1].read_stats()
    assert st["deadline_paused"] >= 1 and st["peers"][0]["deadline_misses"] == 0, st


def test_quiet_health_is_no_miss_while_the_inputs_come(agents, connect):
    """Emulated time: a node's health comes when it changes and once a second, its inputs
    every frame: a health deadline passed while the node's inputs came is no miss."""
    # a deadline well above the inputs' period (a loaded machine stalls a process for tens of
    # milliseconds), passed some four times while node 2 waits for node 1's inputs
    ags = agents(2, extra=["--deadline-ms", "500", "--lease-ms", "60000"])
    c1, c2 = connect(ags[0]), connect(ags[1])
    for c in (c1, c2):
        c.send(xch.HEALTH, 0, 0, xch.pack_health(membership=0b11))
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    for frame in range(1, 15):  # 2.1 s, no health: node 2 waits 150 ms for node 1 each frame
        c2.send_inputs(frame, frame * 50_000_000, inputs_for(2, frame, 0b11))
        time.sleep(0.15)
        c1.send_inputs(frame, frame * 50_000_000, inputs_for(1, frame, 0b11))
        c1.await_agreed(frame, 10)
        c2.await_agreed(frame, 10)
    for a in ags:
        a.stop()
    # (the start-up's frame 0 may outlast a deadline on a loaded machine: real time is real)
    assert not [m for m in ags[1].of_kind("dds_deadline_missed") if m["t_ns"] > 0]
    assert ags[1].read_stats()["deadline_covered"] >= 2


def test_hung_peer_is_not_waited_for_after_a_lease(agents, connect):
    """Emulated time: node 2's agent lives on but its io froze (a hung processor)."""
    ags = agents(2, extra=["--lease-ms", "400", "--deadline-ms", "100"])
    c1, c2 = connect(ags[0]), connect(ags[1])
    for c in (c1, c2):
        c.send(xch.HEALTH, 0, 0, xch.pack_health(membership=0b11))
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    # node 2 goes silent, its io link still open: node 1 waits, then gives up on it
    got, waited = timed_exchange(c1, 1, timeout=10)
    assert got.present == 0b01
    assert 0.4 <= waited < 5.0
    # and never waits for it again
    assert c1.exchange(2, 100_000_000, inputs_for(1, 2, 0b11), timeout=1).present == 0b01
    ags[0].stop()
    (lost,) = ags[0].of_kind("dds_peer_lost")
    assert lost["peer"] == "node2" and lost["reason"] == "hung" and lost["was_alive"]
    assert ags[0].of_kind("dds_deadline_missed", peer="node2")


def test_slow_peer_that_publishes_its_health_is_waited_for(agents, connect):
    ags = agents(2, extra=["--lease-ms", "300", "--deadline-ms", "100"])
    c1, c2 = connect(ags[0]), connect(ags[1])
    exchange_round({1: c1, 2: c2}, 0, {1: 0b11, 2: 0b11})
    c1.send_inputs(1, 50_000_000, inputs_for(1, 1, 0b11))
    for i in range(12):  # 1.2 s: four lease periods, its health on time
        c2.send(xch.HEALTH, i, 0, xch.pack_health(membership=0b11))
        time.sleep(0.1)
    with pytest.raises(TimeoutError):
        c1.await_agreed(1, timeout=0.05)
    c2.send_inputs(1, 50_000_000, inputs_for(2, 1, 0b11))
    assert c1.await_agreed(1).present == 0b11
    ags[0].stop()
    assert not ags[0].of_kind("dds_peer_lost")


def test_missing_agent_at_startup_is_not_waited_for(agent_bin, run_dir, domain):
    from ima.dds.agent import start_agent

    a = start_agent(1, 2, run_dir, domain, extra=["--startup-timeout-ms", "300"], wait=True)
    try:
        c = XchClient(str(a.socket), 1, timeout=5)
        assert c.exchange(0, 0, inputs_for(1, 0, 0b11), timeout=2).present == 0b01
        c.close()
    finally:
        a.stop()
    (lost,) = a.of_kind("dds_peer_lost")
    assert lost["peer"] == "node2" and lost["reason"] == "not_discovered"
    assert a.of_kind("dds_ready")[0]["missing"] == ["node2"]


def test_command_line_errors(agent_bin, run_dir):
    import os
    import subprocess

    env = {k: v for k, v in os.environ.items() if k != "IMA_DDS_CONFIG"}
    base = [str(agent_bin), "--node", "1", "--nodes", "1", "--socket", str(run_dir / "s"),
            "--domain", "7"]
    p = subprocess.run(base, capture_output=True, text=True, env=env, timeout=10)
    assert p.returncode == 2 and "--config" in p.stderr
    p = subprocess.run(base[:-1] + ["300", "--config", "x"], capture_output=True, text=True,
                       env=env, timeout=10)
    assert p.returncode == 2 and "--domain" in p.stderr
    p = subprocess.run(base + ["--config", str(run_dir / "nope.xml")], capture_output=True,
                       text=True, env=env, timeout=10)
    assert p.returncode == 1 and "configuration" in p.stderr


def test_c_client_through_two_agents(agents, run_dir):
    """The io partition's C library against live agents (ima-xch-bench drives it)."""
    import json
    import subprocess

    from ima import paths

    ags = agents(2)
    bench = paths.build_dir() / "nodes" / "dds" / "ima-xch-bench"
    p = subprocess.run([str(bench), "--socket-a", str(ags[0].socket), "--socket-b",
                        str(ags[1].socket), "--count", "30", "--warmup", "5", "--gap-us", "200"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout)
    assert r["samples"] == 30 and r["incomplete"] == 0 and r["median_us"] > 0
    assert r["min_us"] <= r["median_us"] <= r["p95_us"] <= r["max_us"]
    for a in ags:
        a.stop()
    # node1 took node2's inputs of the 35 rounds (warm-up included) as they came
    assert ags[0].read_stats()["dds_latency_us"]["count"] == 35


def _raw_io(agent) -> socket.socket:
    """A connection to the agent's io socket that has said HELLO and had its WELCOME."""
    s = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    s.settimeout(10)
    s.connect(str(agent.socket))
    s.send(xch.pack_hdr(xch.HELLO, agent.node))
    assert len(s.recv(4096)) == xch.HDR.size  # WELCOME
    return s


def test_a_flood_of_bad_datagrams_is_traced_up_to_a_bound(agents):
    (a,) = agents(1)
    raw = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    raw.connect(str(a.socket))
    raw.send(xch.pack_hdr(xch.HELLO, 1) + b"\x00")  # a HELLO of the wrong size: link closed
    raw.settimeout(10)
    assert raw.recv(4096) == b""
    raw.close()
    raw = _raw_io(a)
    for _ in range(1005):
        raw.send(b"\x00" * 10)
    raw.send(xch.pack_hdr(xch.INPUTS, 1) + inputs_for(1, 0, 0b1).pack())  # still served
    assert xch.unpack_agreed(raw.recv(4096)).present == 0b1
    raw.close()
    a.stop()
    assert a.read_stats()["bad_datagrams"] == 1006
    traced = a.of_kind("bad_datagram")
    assert len(traced) == 1000 and "more" in traced[-1] and "more" not in traced[-2]
    assert [e["reason"] for e in a.of_kind("io_disconnect")] == ["bad_hello", "closed"]


def test_a_second_io_waits_until_the_first_link_closes(agents):
    """io restarted by its SKE while its old link is still open: the newcomer waits, and
    becomes io once the old link is read to its end and closed."""
    (a,) = agents(1)
    first = _raw_io(a)
    second = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    second.settimeout(10)
    second.connect(str(a.socket))
    time.sleep(0.05)  # the agent has accepted it and keeps it waiting
    first.send(xch.pack_hdr(xch.INPUTS, 1, 0) + inputs_for(1, 0, 0b1).pack())
    assert xch.unpack_agreed(first.recv(4096)).present == 0b1  # the first is still io
    first.close()
    second.send(xch.pack_hdr(xch.HELLO, 1))
    assert len(second.recv(4096)) == xch.HDR.size
    second.send(xch.pack_hdr(xch.INPUTS, 1, 1) + inputs_for(1, 1, 0b1).pack())
    assert xch.HDR.unpack_from(second.recv(4096))[4] == 1  # frame 1 answered
    second.close()
    a.stop()
    assert a.read_stats()["io_connections"] == 2
    assert [e["kind"] for e in a.events() if e["kind"].startswith("io_")] == [
        "io_connect", "io_hello", "io_disconnect", "io_connect", "io_hello", "io_disconnect"]


def test_inputs_asked_again_answer_the_old_frame_and_a_stalled_io_is_dropped(agents):
    ags = agents(2)
    raw = _raw_io(ags[0])
    # node 2 says nothing: frame 0 waits; io asks for frame 1 before taking the answer
    raw.send(xch.pack_hdr(xch.INPUTS, 1, 0) + inputs_for(1, 0, 0b11).pack())
    time.sleep(0.05)
    raw.send(xch.pack_hdr(xch.INPUTS, 1, 1) + inputs_for(1, 1, 0b1).pack())
    first, second = raw.recv(4096), raw.recv(4096)
    assert xch.HDR.unpack_from(first)[4] == 0 and xch.unpack_agreed(first).present == 0b01
    assert xch.HDR.unpack_from(second)[4] == 1 and xch.unpack_agreed(second).present == 0b01
    # an io that asks without ever reading the answers fills its socket: the link is dropped
    raw.settimeout(None)
    sent = 0
    try:
        for f in range(2, 20000):
            raw.send(xch.pack_hdr(xch.INPUTS, 1, f) + inputs_for(1, f, 0b1).pack())
            sent += 1
    except OSError:
        pass
    raw.close()
    ags[0].stop()
    st = ags[0].read_stats()
    assert st["superseded"] == 1, st
    assert [e["reason"] for e in ags[0].of_kind("io_disconnect")] == ["io_not_reading"]
    assert sent < 19998


def test_a_peer_gone_once_told_to_stop_is_the_runs_end_not_a_loss(agents, connect):
    """The launcher's stop: every agent stopped, each sent its SIGTERM, then continued. A
    peer's agent gone before this one runs on is traced as `dds_peer_left`, never latched
    lost. (Whether node 1's listener takes node 2's goodbye before its main thread reads the
    SIGTERM is the scheduler's choice: about one run in four here, when an agent that latched
    it would fail this test.)"""
    import signal

    ags = agents(2)
    clients = {a.node: connect(a) for a in ags}
    for frame in range(3):
        exchange_round(clients, frame, {1: 0b11, 2: 0b11})
    a1, a2 = ags
    a1.proc.send_signal(signal.SIGSTOP)
    try:
        a2.stop()  # gone: its goodbye waits in node 1's socket
        time.sleep(0.3)
        a1.proc.send_signal(signal.SIGTERM)  # pending while it is stopped
    finally:
        a1.proc.send_signal(signal.SIGCONT)
    assert a1.stop() == 0
    assert not a1.of_kind("dds_peer_lost")
    assert all(not p["dead"] for p in a1.read_stats()["peers"])
    # it saw node 2 go (its listener may take the goodbye before its main thread stops)
    left = a1.of_kind("dds_peer_left")
    assert all(e["peer"] == "node2" for e in left), left
