# SPDX-License-Identifier: Apache-2.0
"""python -m ima.dds.listen receives what the C agents publish, from a separate process."""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
import time

from ima.dds import dds_env, xch


def test_listener_prints_node_health_of_the_agents(agents, connect, domain):
    ags = agents(2, security="off")  # the listener has no security plugins
    clients = [connect(a) for a in ags]
    listener = subprocess.Popen(
        [sys.executable, "-m", "ima.dds.listen", "--domain", str(domain), "--topic",
         "rpas_NodeHealth", "--count", "6", "--timeout", "30", "--json"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dds_env())
    frame = 0
    end = time.monotonic() + 30
    while listener.poll() is None and time.monotonic() < end:
        for c in clients:
            c.send(xch.HEALTH, frame, frame * 50_000_000,
                   xch.pack_health(membership=0b11, flags=xch.HEALTH_NAV_VALID, fcs_mode=2,
                                   failed=c.node))
        frame += 1
        time.sleep(0.05)
    out, err = listener.communicate(timeout=10)
    assert listener.returncode == 0, err
    lines = [json.loads(line) for line in out.splitlines()]
    assert len(lines) == 6
    assert {e["topic"] for e in lines} == {"rpas_NodeHealth"}
    assert all(e["valid"] for e in lines)
    by_node = {}
    for e in lines:
        s = e["sample"]
        assert (s["membership"], s["flags"], s["fcs_mode"]) == (0b11, xch.HEALTH_NAV_VALID, 2)
        assert s["failed"] == s["node"] and s["t_ns"] == s["frame"] * 50_000_000
        by_node.setdefault(s["node"], []).append(s["frame"])
    assert set(by_node) == {1, 2}
    for frames in by_node.values():
        assert frames == sorted(frames)  # in order per node


def test_listener_text_output_and_timeout(agents, connect, domain):
    ags = agents(1, security="off")
    c = connect(ags[0])
    c.send(xch.MISSION, 3, 150_000_000, xch.pack_mission(mode=2, alt_ft=3000.0, ias_kt=100.0))
    p = subprocess.run([sys.executable, "-m", "ima.dds.listen", "--domain", str(domain),
                        "--count", "5", "--timeout", "2"], capture_output=True, text=True,
                       env=dds_env(), timeout=30)
    # the mission sample is retained by its writer (transient local): the listener gets it
    assert "rpas_MissionData node1 frame 3" in p.stdout and "alt_ft=3000" in p.stdout
    assert p.returncode == 1  # fewer than --count samples before the timeout


def test_listener_reports_instance_state_changes(agents, connect, domain):
    """An io link that drops disposes its node's inputs; an agent that ends leaves no writers."""
    ags = agents(2, security="off")  # the listener has no security plugins
    c1, c2 = connect(ags[0]), connect(ags[1])
    listener = subprocess.Popen(
        [sys.executable, "-m", "ima.dds.listen", "--domain", str(domain), "--topic",
         "rpas_CrossChannelInputs", "--timeout", "60", "--json"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dds_env())
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(x) for x in listener.stdout], daemon=True).start()
    got: set = set()

    def until(wanted, poke=None, within=30.0):
        end = time.monotonic() + within
        while not wanted <= got and time.monotonic() < end:
            if poke:
                poke()
            try:
                e = json.loads(lines.get(timeout=0.2))
            except queue.Empty:
                continue
            node = e["sample"]["node"] if e["valid"] else e["node"]
            if e["valid"]:
                got.add((node, "valid"))
            if e["instance_state"] != "alive":  # on its own sample, or on one still unread
                got.add((node, e["instance_state"]))
        assert wanted <= got, (got, listener.poll() is not None and listener.stderr.read())

    frame = iter(range(1, 10_000))

    def publish():  # until the listener has matched the writers, samples may go unseen
        f = next(frame)
        for c in (c1, c2):
            c.exchange(f, f * 50_000_000, xch.Inputs(valid=1, wait_mask=0), timeout=5)

    try:
        until({(1, "valid"), (2, "valid")}, poke=publish)
        c1.close()  # node 1's io goes: its agent disposes node 1's inputs
        until({(1, "disposed")})
        ags[1].stop()  # node 2's agent ends: its writer goes
        until({(2, "no_writers")})
    finally:
        listener.terminate()
        listener.wait(timeout=10)
    assert got == {(1, "valid"), (1, "disposed"), (2, "valid"), (2, "no_writers")}
