# SPDX-License-Identifier: Apache-2.0
"""Where the repository, the build tree and the built programs are."""

from __future__ import annotations

import os
from pathlib import Path

from ima.errors import ImaError


def repo_root() -> Path:
    """The repository root: $IMA_ROOT (set by ./ima), else found from this file's location."""
    env = os.environ.get("IMA_ROOT")
    if env:
        return Path(env)
    # python/ima/paths.py -> the repository root is two folders above the package.
    return Path(__file__).resolve().parents[2]


def build_dir() -> Path:
    """The CMake build tree: $IMA_BUILD_DIR (set by ./ima), else <root>/build."""
    env = os.environ.get("IMA_BUILD_DIR")
    if env:
        return Path(env)
    return repo_root() / "build"


def ske_binary() -> Path:
    """The separation kernel emulator program; raises ImaError if it has not been built."""
    path = build_dir() / "ske" / "ima-ske"
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise ImaError(
            f"ima-ske not built: run ./ima (it builds) or `cmake --build {build_dir()}`; "
            f"expected {path}"
        )
    return path


def examples_dir() -> Path:
    """The example module configurations shipped with the repository."""
    return repo_root() / "config" / "examples"


def tests_dir() -> Path:
    """The integration and system tests (pytest) of the repository."""
    return repo_root() / "tests"
