# SPDX-License-Identifier: Apache-2.0
"""ima/dds/types.py mirrors nodes/dds/rpas.idl and interoperates with the C agent on the wire."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import typing
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
