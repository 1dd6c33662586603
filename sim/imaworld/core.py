# SPDX-License-Identifier: Apache-2.0
"""The world's C++ (sim/core/*.cc, the module imaworld._core in the build tree): its physics
steps (stepper.py), the AHRS's and air data computer's samples (sensors.py) and the truth
record (world.py).

It computes what the Python computes, to the bit, on the same objects: the aircraft's own
JSBSim (through the functions the `jsbsim` wheel's library exports) and the same noise streams.
It is found at <build dir>/sim/_core.<abi>.so ($IMA_BUILD_DIR, else <repo>/build; ./ima builds
it). When it is missing, or cannot drive this JSBSim, the world runs its Python, as it always
could, and says so once on stderr: the same flight, slower.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
from pathlib import Path

DONE, TARGET, JUDGE = 0, 1, 2  # what Stepper.run returns
# What the module's constructors raise when they cannot work on what they are given (another
# JSBSim, say): the world then runs its Python.
REFUSALS = (TypeError, ValueError, ImportError, AttributeError)

_module = None
_why_not: str | None = None


def module_path() -> Path:
    from ima import paths
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    return paths.build_dir() / "sim" / f"_core{suffix}"


def load():
    """The extension module, or None (why_not() says why)."""
    global _module, _why_not
    if _module is not None or _why_not is not None:
        return _module
    path = module_path()
    if not path.is_file():
        _why_not = f"{path} is not built (./ima builds it)"
        return None
    try:
        spec = importlib.util.spec_from_file_location("imaworld._core", path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
    except ImportError as e:
        _why_not = f"cannot load {path}: {e}"
        return None
    if getattr(mod, "SOURCE", None) != source_digest():
        _why_not = f"{path} was not built from this source (./ima builds it)"
        return None
    _module = mod
    return mod


def jsbsim_library(fdm) -> str:
    """The file of the jsbsim wheel's library that this FGFDMExec comes from (ImportError if
    it cannot be told)."""
    import jsbsim

    for mod in (sys.modules.get(type(fdm).__module__), getattr(jsbsim, "_jsbsim", None)):
        path = getattr(mod, "__file__", None)
        if path:
            return path
    raise ImportError("cannot tell which file JSBSim's library was loaded from")


def source_digest() -> str | None:
    """The digest of sim/core's sources, as the build compiles it into the module (SOURCE;
    sim/CMakeLists.txt): a module built from other sources is not used. None if the sources
    are not beside this package."""
    import hashlib

    src = Path(__file__).resolve().parents[1] / "core"
    files = sorted(p for p in src.glob("*") if p.suffix in (".cc", ".h"))
    if not files:
        return None
    h = hashlib.sha256()
    for p in files:
        h.update(p.name.encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def why_not() -> str | None:
    return _why_not


def unavailable(what: str, reason: str) -> None:
    """Say once on stderr that the world runs its Python for `what`, and why."""
    if what not in _told:
        _told.add(what)
        print(f"imaworld: {what} in Python ({reason})", file=sys.stderr)


_told: set[str] = set()
