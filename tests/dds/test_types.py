# SPDX-License-Identifier: Apache-2.0
"""ima/dds/types.py mirrors nodes/dds/rpas.idl and interoperates with the C agent on the wire."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
import typing
from collections import Counter
from pathlib import Path

from dds_helpers import inputs_for

from ima.dds import dds_env, types
from ima.dds.agent import start_agent
from ima.dds.xch import XchClient

HERE = Path(__file__).resolve().parent
IDL = HERE.parents[1] / "nodes" / "dds" / "rpas.idl"
IDL_TYPES = {"uint32": "uint32", "int64": "int64", "double": "float64"}


def idl_structs() -> dict[str, list[tuple[str, str, bool]]]:
    """struct name -> [(field, type as cyclonedds spells it, is key)] from rpas.idl."""
    text = re.sub(r"//[^\n]*", "", IDL.read_text())
    out = {}
    for name, body in re.findall(r"struct\s+(\w+)\s*\{(.*?)\};", text, re.S):
        fields = []
        for key, typ, fname, length in re.findall(r"(@key\s+)?(\w+)\s+(\w+)(?:\[(\d+)\])?;",
                                                  body):
            t = IDL_TYPES[typ]
            fields.append((fname, f"array[{t}, {length}]" if length else t, bool(key)))
        out[name] = fields
    return out


def py_fields(cls) -> list[tuple[str, str, bool]]:
    hints = typing.get_type_hints(cls, include_extras=True)
    keys = {k for k, v in getattr(cls, "__idl_field_annotations__", {}).items() if v.get("key")}
    return [(n, str(h.__metadata__[0]), n in keys) for n, h in hints.items()]


def test_types_mirror_the_idl():
    structs = idl_structs()
    assert list(structs) == ["CrossChannelInputs", "NodeHealth", "Telemetry", "MissionData"]
    assert list(types.TOPICS) == [f"rpas_{n}" for n in structs]
    for name, fields in structs.items():
        cls = types.TOPICS[f"rpas_{name}"]
        assert cls.__idl_typename__ == f"rpas::{name}"
        assert cls.__idl_annotations__.get("extensibility") == "final"
        assert py_fields(cls) == fields, name
        assert fields[0] == ("node", "uint32", True) and fields[1][0] == "frame"


def test_python_and_c_agents_exchange_inputs(agent_bin, run_dir, domain):
    """A Python 'agent' of node 2 and the C agent of node 1: each reads what the other writes."""
    a = start_agent(1, 2, run_dir, domain, security="off")  # pypeer has no security plugins
    peer = subprocess.Popen([sys.executable, str(HERE / "pypeer.py"), "--domain", str(domain),
                             "--node", "2", "--frames", "3"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=dds_env())
    try:
        a.wait_ready()
        assert a.of_kind("dds_ready")[0]["discovered"] == ["node2"]
        c = XchClient(str(a.socket), 1, timeout=10)
        for f in range(3):
            got = c.exchange(f, f * 50_000_000, inputs_for(1, f, 0b11), timeout=10)
            assert got.present == 0b11
            assert got.of(2) == inputs_for(2, f, 0b11)  # written by Python, read by C
        out, err = peer.communicate(timeout=30)
        assert peer.returncode == 0, err
        seen = [json.loads(line) for line in out.splitlines()]
        assert [s["frame"] for s in seen] == [0, 1, 2]
        for s in seen:  # written by C, read by Python
            x = inputs_for(1, s["frame"], 0b11)
            assert s["node"] == 1 and s["t_ns"] == s["frame"] * 50_000_000
            assert (s["gps_seq"], s["gps"], s["ahrs"], s["air"]) == (x.gps_seq, x.gps, x.ahrs,
                                                                     x.air)
        c.close()
    finally:
        if peer.poll() is None:
            peer.kill()
        a.stop()


def test_writers_outside_a_node_partition_are_refused_and_listed(agent_bin, run_dir, domain):
    """Without DDS Security, a participant may write in any partition: the agent takes a
    sample's node from the one node partition its writer writes in, and refuses the sample
    otherwise (another node's partition, two partitions, a wildcard). Refused writers are
    listed while the table has room, counted always; the participant is reported."""
    a = start_agent(1, 2, run_dir, domain, security="off", extra=["--startup-timeout-ms", "300"])
    a.wait_ready()
    writers = ["node2:1",          # node 2's partition, keyed as node 1
               "node2,node1:2",    # two node partitions: no node
               "node*:2",          # a wildcard matches every node's reader: no node
               "node2:2",          # node 2's own: taken
               "node2:1:62"]       # 62 more keyed as node 1: fill the agent's table of writers
    forger = subprocess.Popen([sys.executable, str(HERE / "pyforger.py"), "--domain",
                               str(domain), "--gone", "4",
                               *(x for w in writers for x in ("--writer", w))],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=dds_env())
    try:
        assert forger.stdout.readline().strip() == "done", forger.stderr.read()
        time.sleep(0.5)  # the last samples reach the agent
        assert a.stop() == 0, a.stderr_text()
    finally:
        forger.stdin.close()
        forger.wait(timeout=30)
        forger.stderr.close()
    st = a.read_stats()
    # 65 refused; the table of 64 writers forgot the 4 gone ones, kept the taken one, and
    # listed refusing writers until it was full: the last 2 are counted only
    assert st["refused_samples"] == 65, st
    refused = [(r["partition"], r["claimed_node"], r["samples"]) for r in st["refused"]]
    assert len(refused) == 63
    assert Counter(refused) == {("node2", 1, 1): 61, ("", 2, 1): 1, ("node*", 2, 1): 1}
    assert st["topics"]["rpas_CrossChannelInputs"]["read"] >= 5, st["topics"]  # the gone 4 and node2:2
    (p,) = st["foreign_participants"]
    assert p["refused"] and p["pid"] == forger.pid, p
    traced = [(e["partition"], e["claimed_node"]) for e in a.of_kind("dds_refused")]
    assert Counter(traced) == {("node2", 1): 61, ("", 2): 1, ("node*", 2): 1}
