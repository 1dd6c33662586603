# SPDX-License-Identifier: Apache-2.0
"""ima/dds/xch.py mirrors nodes/include/xch/proto.h: sizes, offsets and constants, compiled."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from ima.dds import xch

ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "nodes" / "include"
HEADER = INCLUDE / "xch" / "proto.h"

STRUCTS = {
    "xch_hdr": xch.HDR_FIELDS,
    "xch_inputs": xch.INPUTS_FIELDS,
    "xch_health": xch.HEALTH_FIELDS,
    "xch_telemetry": xch.TELEMETRY_FIELDS,
    "xch_mission": xch.MISSION_FIELDS,
}


@pytest.fixture(scope="module")
def layout(tmp_path_factory) -> dict[str, int]:
    """name -> value printed by a C program compiled against the header."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if not cc:
        pytest.fail("no C compiler to check the header layout")
    lines = ['#include <stddef.h>', '#include <stdio.h>', '#include "xch/proto.h"',
             "int main(void) {"]
    for struct, fs in STRUCTS.items():
        lines.append(f'  printf("sizeof.{struct} %zu\\n", sizeof(struct {struct}));')
        for name, _ in fs:
            lines.append(f'  printf("{struct}.{name} %zu\\n", offsetof(struct {struct}, {name}));')
    lines.append('  printf("sizeof.xch_agreed %zu\\n", sizeof(struct xch_agreed));')
    lines.append('  printf("xch_agreed.in %zu\\n", offsetof(struct xch_agreed, in));')
    lines.append("  return 0;\n}")
    d = tmp_path_factory.mktemp("xchlayout")
    src, exe = d / "layout.c", d / "layout"
    src.write_text("\n".join(lines) + "\n")
    subprocess.run([cc, "-std=c11", "-Wall", "-Werror", "-I", str(INCLUDE), "-o", str(exe),
                    str(src)], check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    return {k: int(v) for k, v in (line.split() for line in out.splitlines())}


@pytest.mark.parametrize("struct", list(STRUCTS))
def test_offsets_and_sizes_match_the_header(layout, struct):
    fs = STRUCTS[struct]
    for name, off in xch.offsets(fs).items():
        assert layout[f"{struct}.{name}"] == off, f"{struct}.{name}"
    size = sum(__import__("struct").calcsize("<" + f) for _, f in fs)
    assert layout[f"sizeof.{struct}"] == size


def test_payload_sizes(layout):
    assert xch.PAYLOAD_SIZE[xch.INPUTS] == layout["sizeof.xch_inputs"] == 200
    assert xch.PAYLOAD_SIZE[xch.AGREED] == layout["sizeof.xch_agreed"]
    assert layout["xch_agreed.in"] == xch.AGREED_HEAD.size
    assert xch.PAYLOAD_SIZE[xch.HEALTH] == layout["sizeof.xch_health"]
    assert xch.PAYLOAD_SIZE[xch.TELEMETRY] == layout["sizeof.xch_telemetry"]
    assert xch.PAYLOAD_SIZE[xch.MISSION] == layout["sizeof.xch_mission"]
    assert xch.HDR.size == layout["sizeof.xch_hdr"] == 24


def test_every_header_constant_is_mirrored():
    text = HEADER.read_text()
    consts = {n: int(v, 0) for n, v in
              re.findall(r"#define\s+XCH_(\w+)\s+(0x[0-9a-fA-F]+|\d+)u?\b", text)}
    for body in re.findall(r"enum\s+\w+\s*\{(.*?)\}", text, re.S):
        consts.update({n: int(v) for n, v in re.findall(r"XCH_(\w+)\s*=\s*(\d+)", body)})
    assert len(consts) >= 15
    for name, val in consts.items():
        assert getattr(xch, name, None) == val, f"xch.py lacks XCH_{name} = {val}"


def test_magic_spells_ixch():
    assert xch.MAGIC.to_bytes(4, "little") == b"IXCH"


def test_inputs_roundtrip():
    i = xch.Inputs(valid=5, wait_mask=3, gps_seq=9, gps=[1.0, 2, 3, 4, 5], air=[7.0, 8, 9])
    assert xch.Inputs.unpack(i.pack()) == i
