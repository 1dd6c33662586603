# SPDX-License-Identifier: Apache-2.0
"""The physics steps in C++ (sim/core/stepper.cc, the module imaworld._stepper in the build
tree): World.advance hands it every step it can, and takes back the rare ones.

The module drives the aircraft's own JSBSim object through the functions the `jsbsim` wheel's
library exports, so it computes what the Python steps compute, to the bit. It is found at
<build dir>/sim/_stepper.<abi>.so ($IMA_BUILD_DIR, else <repo>/build; ./ima builds it). When
it is missing, or this JSBSim is not laid out as it expects, the world steps in Python, as it
always could, and says so once on stderr: same results, slower.
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
    return paths.build_dir() / "sim" / f"_stepper{suffix}"


def _load():
    """The extension module, or None (the reason in _why_not)."""
    global _module, _why_not
    if _module is not None or _why_not is not None:
        return _module
    path = module_path()
    if not path.is_file():
        _why_not = f"{path} is not built (./ima builds it)"
        return None
    try:
        spec = importlib.util.spec_from_file_location("imaworld._stepper", path)
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


def make(ac, act, limits, near_ground_ft: float, hz: int):
    """A Stepper for this aircraft and these actuators, or None: the world then steps in
    Python (told once on stderr, with the reason)."""
    global _why_not
    mod = _load()
    if mod is not None:
        lib = sys.modules[type(ac.fdm).__module__].__file__
        dt = 1.0 / hz
        try:
            st = mod.Stepper(lib, ac.fdm, ac.ctl_node, ac.node["agl"], ac.node["phi"],
                             ac.node["cas"], ac.node["nz"], act.lo, act.hi,
                             act.moves(dt), hz, limits.max_roll_deg, limits.max_cas_kt,
                             limits.max_load_g, near_ground_ft)
        except (TypeError, ImportError, ValueError) as e:
            _why_not = f"this JSBSim cannot be stepped from C++: {e}"
            st = None
        if st is not None and _reads_as_python(st, ac):
            return st
        if st is not None:
            _why_not = "this JSBSim's property nodes read otherwise from C++"
    if _why_not is not None:
        print(f"imaworld: stepping the physics in Python ({_why_not})", file=sys.stderr)
        _why_not = ""  # told once
    return None


def _reads_as_python(st, ac) -> bool:
    """The C++ reads each property node the stepper uses as the Python reads it."""
    nodes = [ac.node[k] for k in ("agl", "phi", "cas", "nz")] + list(ac.ctl_node)
    return all(st.get(nd) == nd.get_double_value() for nd in nodes)
