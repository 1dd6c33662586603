# SPDX-License-Identifier: Apache-2.0
"""python -m ima.dds.listen receives what the C agents publish, from a separate process."""

from __future__ import annotations

import json
import subprocess
import sys
import time

from ima.dds import dds_env, xch


def test_listener_prints_node_health_of_the_agents(agents, connect, domain):
    ags = agents(2)
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
    ags = agents(1)
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
    ags = agents(2)
    c1, c2 = connect(ags[0]), connect(ags[1])
    listener = subprocess.Popen(
        [sys.executable, "-m", "ima.dds.listen", "--domain", str(domain), "--topic",
         "rpas_CrossChannelInputs", "--count", "4", "--timeout", "30", "--json"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dds_env())
    time.sleep(1.0)  # matched by then
    for c in (c1, c2):
        c.exchange(0, 0, xch.Inputs(valid=1, wait_mask=0), timeout=5)  # waits for nobody
    c1.close()  # node 1's io goes: its agent disposes node 1's inputs
    time.sleep(0.2)
    ags[1].stop()  # node 2's agent ends: its writer goes
    out, err = listener.communicate(timeout=40)
    assert listener.returncode == 0, err
    got = {(e.get("node") or e["sample"]["node"], e.get("instance_state", "valid"))
           for e in map(json.loads, out.splitlines())}
    assert got == {(1, "valid"), (1, "disposed"), (2, "valid"), (2, "no_writers")}
