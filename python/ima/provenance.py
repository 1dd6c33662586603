# SPDX-License-Identifier: Apache-2.0
"""Where a result comes from: the product's commit (and whether the tree had changes), the
versions of JSBSim and Cyclone DDS, the command line. Every summary, campaign result line and
report carries it."""

from __future__ import annotations

import functools
import shutil
import subprocess
import sys
from importlib import metadata

from ima import __version__, paths


@functools.cache
def _git() -> dict:
    root = paths.repo_root()
    if shutil.which("git") is None or not (root / ".git").exists():
        return {"commit": None, "dirty": None}
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                                text=True, timeout=10).stdout.strip() or None
        status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                                cwd=root, capture_output=True, text=True, timeout=10)
        dirty = bool(status.stdout.strip()) if status.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}
    return {"commit": commit, "dirty": dirty}


def _version(dist: str) -> str | None:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


@functools.cache
def _cyclonedds() -> str | None:
    """The Cyclone DDS C library the agents link (Debian's cyclonedds-dev)."""
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "cyclonedds-dev"],
                             capture_output=True, text=True, timeout=10)
        return out.stdout.strip() or None if out.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(argv: list[str] | None = None) -> dict:
    return {**_git(), "ima": __version__, "jsbsim": _version("jsbsim"),
            "cyclonedds": _cyclonedds(), "python": sys.version.split()[0],
            "command": list(sys.argv if argv is None else argv)}
