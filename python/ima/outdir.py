# SPDX-License-Identifier: Apache-2.0
"""The folders the product writes into (a run directory, a campaign folder, a deployment),
checked before anything starts: named (an empty name is not the current directory), a
directory or creatable as one, on a file system that takes files, and writable."""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from ima.errors import ImaError

# Pseudo file systems: a run written there would be lost or refused file by file.
_REFUSED_ROOTS = ("/proc", "/sys", "/dev")


def dir_arg(text: str) -> Path:
    """An argparse type for a folder: any path but the empty one."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty folder name (write . for the current folder)")
    if "\0" in text:
        raise argparse.ArgumentTypeError("a folder name holds no NUL character")
    return Path(text)


def usable_dir(path: Path, option: str) -> Path:
    """path, made if missing and checked writable (a file created and removed in it);
    ImaError (exit 2) naming the option and the reason otherwise."""
    path = Path(path)
    absolute = Path(os.path.abspath(path))
    if any(absolute == Path(r) or Path(r) in absolute.parents for r in _REFUSED_ROOTS):
        raise ImaError(f"{option} {path}: under {absolute.parts[1] and '/' + absolute.parts[1]}, "
                       "a pseudo file system: choose a folder on a disk", exit_code=2)
    if path.exists() and not path.is_dir():
        raise ImaError(f"{option} {path}: exists and is not a folder", exit_code=2)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ImaError(f"{option} {path}: cannot create the folder: {exc.strerror}",
                       exit_code=2) from exc
    try:
        with tempfile.NamedTemporaryFile(dir=path, prefix=".ima-write-check-"):
            pass
    except OSError as exc:
        raise ImaError(f"{option} {path}: cannot write in it: {exc.strerror}",
                       exit_code=2) from exc
    return path
