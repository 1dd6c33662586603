# SPDX-License-Identifier: Apache-2.0
"""The physics steps in C++ (sim/core/stepper.cc, the Stepper of imaworld._core: core.py):
World.advance hands it every step it can, and takes back the rare ones."""

from __future__ import annotations

from . import core
from .core import DONE, JUDGE, TARGET

__all__ = ["DONE", "JUDGE", "TARGET", "make"]


def make(mod, ac, act, limits, near_ground_ft: float, hz: int):
    """A Stepper (mod: the module imaworld._core) for this aircraft and these actuators, or
    None: the world then steps in Python (told once on stderr, with the reason)."""
    try:
        node = ac.node
        st = mod.Stepper(core.jsbsim_library(ac.fdm), ac.fdm, ac.ctl_node, node["agl"],
                         node["phi"], node["cas"], node["nz"], act.lo, act.hi,
                         act.moves(1.0 / hz), hz, limits.max_roll_deg, limits.max_cas_kt,
                         limits.max_load_g, near_ground_ft)
    except core.REFUSALS as e:
        core.unavailable("stepping the physics", f"this JSBSim cannot be stepped from C++: {e}")
        return None
    nodes = [ac.node[k] for k in ("agl", "phi", "cas", "nz")] + list(ac.ctl_node)
    if not all(st.get(nd) == nd.get_double_value() for nd in nodes):
        core.unavailable("stepping the physics", "its property nodes read otherwise from C++")
        return None
    return st
