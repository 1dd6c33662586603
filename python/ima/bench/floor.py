# SPDX-License-Identifier: Apache-2.0
"""The floor of a flight's cost: the CPU work per emulated second that no lockstep can avoid,
estimated from measured parts (docs/performance.md, "The floor"):

- JSBSim alone: the c172p stepped at the world's physics rate, trimmed, in light turbulence,
  timed here (CPU time of this process);
- the partitions' own computation: their CPU time in the flight measured beside it;
- the minimal hand-offs: each partition window is two context switches (SKE → partition →
  SKE), each instant at which a node has work one grant and one answer between the time
  master and each lockstep client, and with several nodes one cross-channel message from each
  node to each other node per major frame, each a send and a wake-up on the other side."""

from __future__ import annotations

import os
import sys
import time

# The RPAS application's schedule (config/applications/rpas.yaml): per 50 ms major frame, 5
# windows (io rx, nav_fcs, io tx, fdr, mission_manager), starting at 3 distinct quanta of the
# 10 ms grid (0 ms: io rx and nav_fcs; 20 ms: io tx and fdr; 30 ms: the mission manager), and
# the world has sensor frames to send in each of them.
FRAMES_PER_S = 20
WINDOWS_PER_FRAME = 5
WORK_INSTANTS_PER_FRAME = 3


def jsbsim_ms_per_emulated_s(seconds: float = 20.0) -> float:
    """CPU milliseconds JSBSim takes per emulated second, stepping alone."""
    from imaworld.config import DEFAULT
    from imaworld.fdm import Aircraft

    start = {"lat_deg": 47.0, "lon_deg": 8.0, "altitude_ft": 3000.0, "airspeed_kt": 100.0,
             "heading_deg": 90.0}
    # JSBSim writes its banner on fd 1: keep it off the benchmark's JSON
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        ac = Aircraft(DEFAULT, start, seed=1, terrain_ft=0.0, wind=(10.0, 270.0))
        ac.trim()
    finally:
        os.dup2(saved, 1)
        os.close(saved)
    ac.set_turbulence(*DEFAULT.atmosphere.turbulence["light"])
    steps = int(seconds * DEFAULT.physics_hz)
    run = ac.run
    best = float("inf")
    for _ in range(3):  # the least of three: what the machine's noise did not add
        t0 = time.process_time()
        for _ in range(steps):
            run()
        best = min(best, time.process_time() - t0)
    return best * 1000.0 / seconds


# What one context switch pair, one hand-off and one cross-channel message cost on one CPU of
# these machines (two context switches ≈ 5 µs; a DDS message with its signature, sent and
# taken, about four times that): assumptions, printed with the estimate.
SWITCH_US = 5.0
HANDOFF_US = 5.0
MESSAGE_US = 20.0


def estimate(nodes: int, partitions_ms: float, jsbsim_ms: float, switch_us: float = SWITCH_US,
             handoff_us: float = HANDOFF_US, message_us: float = MESSAGE_US) -> dict:
    """The floor in CPU ms per emulated second, term by term, and the speed-up it allows on
    one CPU. switch_us: one window (two context switches); handoff_us: one message and the
    wake-up it causes; message_us: one cross-channel DDS message, sent and taken."""
    windows = nodes * WINDOWS_PER_FRAME * FRAMES_PER_S * switch_us / 1000.0
    clients = nodes + 1  # each node's SKE and the world
    grants = WORK_INSTANTS_PER_FRAME * FRAMES_PER_S * clients * 2 * handoff_us / 1000.0
    xch = nodes * (nodes - 1) * FRAMES_PER_S * message_us / 1000.0 if nodes > 1 else 0.0
    terms = {"jsbsim": round(jsbsim_ms, 2), "partitions": round(partitions_ms, 2),
             "windows": round(windows, 2), "lockstep": round(grants, 2),
             "cross_channel": round(xch, 2)}
    total = sum(terms.values())
    return {"ms_per_emulated_s": terms, "total_ms_per_emulated_s": round(total, 2),
            "speedup_floor": round(1000.0 / total, 1) if total > 0 else None,
            "assumed": {"window_switch_us": switch_us, "handoff_us": handoff_us,
                        "cross_channel_message_us": message_us}}
