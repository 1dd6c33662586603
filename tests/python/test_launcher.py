# SPDX-License-Identifier: Apache-2.0
"""Tests of the ./ima launcher's first step: missing Debian packages are named in one line."""

from __future__ import annotations

import subprocess
from pathlib import Path

from ima import paths

REQUIRED = [
    "build-essential",
    "cmake",
    "ninja-build",
    "pkg-config",
    "libxml2-dev",
    "libxml2-utils",
    "libseccomp-dev",
    "python3-venv",
    "python3-dev",
    "cyclonedds-dev",
    "cyclonedds-tools",
    "openssl",
]


def _fake_tools(bin_dir: Path, installed: list[str]) -> None:
    bin_dir.mkdir()
    lines = "".join(f"{name} install ok installed\\n" for name in installed)
    (bin_dir / "dpkg-query").write_text(f"#!/bin/sh\nprintf '{lines}'\nexit 1\n")
    (bin_dir / "id").write_text("#!/bin/sh\necho 1000\n")  # not root: must not install
    for tool in bin_dir.iterdir():
        tool.chmod(0o755)


def test_non_root_gets_one_line_naming_missing_packages(tmp_path):
    bin_dir = tmp_path / "bin"
    _fake_tools(bin_dir, [p for p in REQUIRED if p not in ("libxml2-utils", "python3-dev")])
    launcher = paths.repo_root() / "ima"
    done = subprocess.run(
        [str(launcher), "--help"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=30,
        env={"PATH": f"{bin_dir}:/usr/bin:/bin", "HOME": str(tmp_path)},
    )
    assert done.returncode == 1
    assert done.stdout == ""
    assert done.stderr == (
        "ima: missing Debian packages: libxml2-utils python3-dev — run: "
        "sudo apt-get install libxml2-utils python3-dev\n"
    )
