# SPDX-License-Identifier: Apache-2.0
"""The system model is the one source of the deployment: in a scratch copy of the source tree,
a new port carrying a new struct from io to nav_fcs is added by editing the model (the shared
partition set) and the two partitions' code only; the build generates the contract, the flight
runs, and nav_fcs reads what io sent."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ima.launch import options as launch_options
from ima.launch import run as launch_run

ROOT = Path(__file__).resolve().parents[2]
SOURCES = ("CMakeLists.txt", "bench", "config", "faultinject", "health_monitor", "nodes",
           "partitions", "python", "ske", "sim", "tests")

MODEL_EDIT = {
    # io's ports: a new source port
    "    ports:\n      - {name: GPS_OUT,":
        "    ports:\n"
        "      - {name: PROBE_OUT, direction: source, kind: sampling, size: 16, refresh_s: 1.0,\n"
        "         message: rpas_probe_msg_t}\n"
        "      - {name: GPS_OUT,",
    # nav_fcs's ports: a new destination port
    "    ports:\n      - {name: GPS_IN,":
        "    ports:\n"
        "      - {name: PROBE_IN, direction: destination, kind: sampling, size: 16, refresh_s: 1.0,\n"
        "         message: rpas_probe_msg_t}\n"
        "      - {name: GPS_IN,",
    # the channel between them
    "  intra_node:\n":
        "  intra_node:\n    - {name: probe, from: io.PROBE_OUT, to: nav_fcs.PROBE_IN}\n",
}

CODE_EDIT = {
    "partitions/include/rpas/ports.h": {
        "#endif\n": "/* io -> nav_fcs: port PROBE_IN */\n"
                    "typedef struct {\n    int64_t t_ns;\n    double value;\n} rpas_probe_msg_t;\n\n"
                    "#endif\n",
    },
    "partitions/io/main.c": {
        "static void write_samples(int64_t t)\n{\n":
            "static void write_samples(int64_t t)\n{\n"
            "    rpas_probe_msg_t probe = {.t_ns = t, .value = 0.25 * io.frame_no + 7.0};\n"
            "    write_port(IO_PORT_PROBE_OUT, &probe, sizeof probe);\n",
    },
    "partitions/nav_fcs/main.c": {
        "        write_port(P_NAV, &nav);\n":
            "        write_port(P_NAV, &nav);\n"
            "        rpas_probe_msg_t probe;\n"
            "        if (read_port(NAV_FCS_PORT_PROBE_IN, &probe) && probe.t_ns % 1000000000 == 0)\n"
            "            rpas_report(\"probe %lld %.2f\", (long long)probe.t_ns, probe.value);\n",
    },
}


def _edit(path: Path, replacements: dict[str, str]) -> None:
    text = path.read_text()
    for old, new in replacements.items():
        assert text.count(old) == 1, f"{path}: the edit's anchor {old!r} is not there once"
        text = text.replace(old, new)
    path.write_text(text)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory) -> Path:
    """A copy of the sources, with the new port in the model and the partitions' code."""
    tree = tmp_path_factory.mktemp("scratch")
    for name in SOURCES:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, tree / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(src, tree / name)
    _edit(tree / "config" / "applications" / "rpas.yaml", MODEL_EDIT)
    for rel, replacements in CODE_EDIT.items():
        _edit(tree / rel, replacements)
    return tree


def test_a_new_port_is_added_in_the_model_and_the_partitions_code(scratch: Path, tmp_path) -> None:
    build = scratch / "build"
    env = dict(os.environ, PYTHONPATH=str(scratch / "python"))
    subprocess.run(["cmake", "-S", str(scratch), "-B", str(build), "-G", "Ninja",
                    "-DCMAKE_BUILD_TYPE=RelWithDebInfo", f"-DIMA_PYTHON={sys.executable}"],
                   check=True, capture_output=True, env=env)
    done = subprocess.run(["cmake", "--build", str(build), "--target", "io", "nav_fcs"],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout[-3000:]
    glue = (build / "generated" / "rpas_glue" / "io_ports.h").read_text()
    assert "IO_PORT_PROBE_OUT_CHANNEL_NAME \"probe\"" in glue

    run_dir = tmp_path / "run"
    opts = launch_options.LaunchOptions(
        system=scratch / "config" / "systems" / "rpas_simplex.yaml", duration_s=5.0, seed=2,
        turbulence="none", run_dir=run_dir, kind="fly", partition_path=[build / "partitions"])
    result = launch_run.launch(opts)
    assert {k: v for k, v in result.returncodes.items() if v not in (0, None)} == {}
    # the node ran the scratch programs, with the new port in its module
    module = (run_dir / "deploy" / "node1.xml").read_text()
    assert 'Name="PROBE_IN"' in module and 'PortName="PROBE_OUT"' in module
    reports = [m.groups() for m in re.finditer(r'"text":"probe (\d+) ([0-9.]+)"',
                                               (run_dir / "node1.jsonl").read_text())]
    assert len(reports) >= 4, reports
    for t_ns, value in reports:
        # io wrote 0.25 * frame + 7 at the start of frame t / 50 ms; nav_fcs read it
        assert float(value) == pytest.approx(0.25 * (int(t_ns) // 50_000_000) + 7.0)
