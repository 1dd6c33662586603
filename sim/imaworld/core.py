# SPDX-License-Identifier: Apache-2.0
"""The world's C++ (sim/core/*.cc, the module imaworld._core in the build tree): its physics
steps (stepper.py) and its sensors' samples (sensors.py).

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
    if (mod.DONE, mod.TARGET, mod.JUDGE) != (DONE, TARGET, JUDGE):
        _why_not = f"{path} was not built from this source"
        return None
    _module = mod
    return mod


def jsbsim_library(fdm) -> str:
    """The file of the jsbsim wheel's library that this FGFDMExec comes from."""
    return sys.modules[type(fdm).__module__].__file__


def why_not() -> str | None:
    return _why_not


def unavailable(what: str, reason: str) -> None:
    """Say once on stderr that the world runs its Python for `what`, and why."""
    global _told
    if what not in _told:
        _told.add(what)
        print(f"imaworld: {what} in Python ({reason})", file=sys.stderr)


_told: set[str] = set()
