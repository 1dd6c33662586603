# SPDX-License-Identifier: Apache-2.0
"""Schema validations remembered by content. Every launch validates the system model and the
pilot script against their JSON Schemas, and the world validates the script again; importing
jsonschema and running it costs some 0.1 s of CPU in each of the two processes. A document
found valid is remembered as an empty file in the build tree (<build>/validated/), named by
the SHA-256 of the schema, the pinned Python packages and the document itself; a document
found there is not validated again.

Only valid documents are remembered: a document with errors is validated every time, and its
messages are always jsonschema's. Anything that changes the document, its schema or the
packages (requirements.lock) changes the name. Where the build tree cannot be written, every
document is simply validated."""

from __future__ import annotations

import hashlib
import os
import pickle
from pathlib import Path
from typing import Any

from ima import paths

_lock_digest: bytes | None = None


def _environment() -> bytes:
    """What else a validation depends on: the pinned packages (jsonschema's version)."""
    global _lock_digest
    if _lock_digest is None:
        try:
            data = (paths.repo_root() / "requirements.lock").read_bytes()
        except OSError:
            data = b""
        _lock_digest = hashlib.sha256(data).digest()
    return _lock_digest


def _stamp(schema: bytes, doc: Any) -> Path | None:
    try:
        blob = pickle.dumps(doc, protocol=4)
    except Exception:  # noqa: BLE001 - a document pickle cannot take is simply validated
        return None
    h = hashlib.sha256(_environment())
    h.update(hashlib.sha256(schema).digest())
    h.update(blob)
    return paths.build_dir() / "validated" / h.hexdigest()


def known_valid(schema: bytes, doc: Any) -> bool:
    """Whether `doc` was found valid against the schema whose text is `schema`."""
    stamp = _stamp(schema, doc)
    try:
        return stamp is not None and stamp.is_file()
    except OSError:  # a build tree it may not look into: validated, then
        return False


def remember_valid(schema: bytes, doc: Any) -> None:
    """Remember that `doc` is valid against `schema` (quietly nothing if it cannot)."""
    stamp = _stamp(schema, doc)
    if stamp is None:
        return
    try:
        stamp.parent.mkdir(parents=True, exist_ok=True)
        tmp = stamp.with_name(f".{stamp.name}.{os.getpid()}")
        tmp.touch()
        os.replace(tmp, stamp)
    except OSError:
        pass
