# SPDX-License-Identifier: Apache-2.0
"""The messages and signals cantools reads from a DBC file, kept in the build tree
(`build/dbc-cache/`, by the file's content): every process of a run reads the DBC (the
deployment, the world, the recorder), and importing cantools alone takes some 90 ms of CPU. A
change of the file, of this layout or of cantools's version is another key; a cache that
cannot be written or read is read around.

A message is {"name", "frame_id", "extended", "length", "cycle_ms", "signals",
"unsupported"}: each signal is ima.canbus.codec.SignalInfo's fields; `unsupported` names the
first signal the fast codec cannot decode (not a plain little-endian integer), else None."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

LAYOUT = 2


def _read(path: Path) -> list[dict]:
    """Every message of a DBC as cantools reads it (raises what cantools raises)."""
    import cantools  # only here: the cache spares every other process the import

    db = cantools.database.load_file(str(path), database_format="dbc", strict=True)
    table = []
    for m in db.messages:
        sigs, unsupported = [], None
        for s in m.signals:
            if unsupported is None and (s.byte_order != "little_endian" or s.is_float
                                        or s.is_multiplexer or s.multiplexer_ids):
                unsupported = f"{m.name}.{s.name}"
            sigs.append({"name": s.name, "start": s.start, "length": s.length,
                         "signed": s.is_signed, "scale": s.scale, "offset": s.offset,
                         "minimum": s.minimum, "maximum": s.maximum,
                         "choices": {int(k): str(v) for k, v in (s.choices or {}).items()}})
        table.append({"name": m.name, "frame_id": m.frame_id, "extended": m.is_extended_frame,
                      "length": m.length, "cycle_ms": m.cycle_time or None, "signals": sigs,
                      "unsupported": unsupported})
    return table


def _cantools_version() -> str:
    """The installed cantools's version, from its distribution's directory name where there is
    exactly one beside the package (importlib.metadata, which scans every distribution and
    imports the email package, costs some 20–30 ms of CPU in each process of a run); else from
    importlib.metadata; "?" without cantools."""
    import importlib.util

    spec = importlib.util.find_spec("cantools")
    if spec is None or not spec.origin:
        return "?"
    site = Path(spec.origin).parent.parent
    try:
        found = [n for n in os.listdir(site)
                 if n.startswith("cantools-") and n.endswith(".dist-info")]
    except OSError:
        found = []
    if len(found) == 1:
        return found[0][len("cantools-"):-len(".dist-info")]
    from importlib import metadata

    try:
        return metadata.version("cantools")
    except metadata.PackageNotFoundError:
        return "?"


def _cache_file(data: bytes) -> Path | None:
    from ima import paths

    build = paths.build_dir()
    if not build.is_dir():
        return None
    key = hashlib.sha256(data + f"\0layout {LAYOUT} cantools {_cantools_version()}".encode()
                         ).hexdigest()[:32]
    return build / "dbc-cache" / f"{key}.json"


def table(path: Path) -> list[dict]:
    """The DBC's messages: from the cache when this very file was read before, else read and
    kept."""
    path = Path(path)
    data = path.read_bytes()
    cache = _cache_file(data)
    if cache is not None:
        try:
            doc = json.loads(cache.read_text())
            if doc.get("layout") == LAYOUT:
                return doc["messages"]
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            pass
    messages = _read(path)
    if cache is not None:
        try:
            cache.parent.mkdir(exist_ok=True)
            tmp = cache.with_name(f"{cache.name}.{os.getpid()}.part")
            tmp.write_text(json.dumps({"layout": LAYOUT, "dbc": str(path),
                                       "messages": messages}))
            os.replace(tmp, cache)
        except OSError:
            pass
    return messages
