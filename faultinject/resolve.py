# SPDX-License-Identifier: Apache-2.0
"""Triggers that are conditions, resolved to emulated times before the run, so that the run
stays deterministic: a fault triggered by `mode=M` starts when the flight control first reports
mode M on the downlink in a run that is the same as the real one up to that instant — a run
with the faults already resolved (faults act only from their start on, so up to the condition
it is the real run). One condition is resolved per such run, in time order."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from faultinject.grammar import FaultSpecError
from faultinject.model import Fault
from faultinject.plan import resolve_after

# A run of the system with these (resolved) faults that may stop once `until(status)` is
# true; returns its run directory.
RunOnce = Callable[[list[Fault], Callable[[dict], bool]], Path]


def mode_reached(run_dir: Path, mode: str) -> float | None:
    """The emulated time (s) of the first truth record whose downlinked mode is `mode`."""
    try:
        with open(run_dir / "truth.jsonl", encoding="utf-8") as f:
            for line in f:
                try:
                    rec = json.loads(line)
                except ValueError:
                    continue
                if rec.get("fcs_mode") == mode:
                    return rec["t_ns"] / 1e9
    except OSError:
        return None
    return None


def resolve(faults: list[Fault], run_once: RunOnce, duration_s: float) -> list[Fault]:
    """Every trigger resolved; FaultSpecError if a condition never comes true in the run."""
    faults = resolve_after(faults)
    while True:
        pending = [f for f in faults if f.trigger.at_s is None and f.trigger.mode is not None]
        if not pending:
            break
        resolved = [f for f in faults if f.trigger.at_s is not None]
        modes = {f.trigger.mode for f in pending}
        run_dir = run_once(resolved, lambda st, modes=modes: st.get("mode") in modes)
        found = {m: mode_reached(run_dir, m) for m in modes}
        candidates = [(found[f.trigger.mode], i, f) for i, f in enumerate(pending)
                      if found[f.trigger.mode] is not None]
        if not candidates:
            f = pending[0]
            raise FaultSpecError(f"fault {f.fid} ({f.spec()}): mode {f.trigger.mode} never came "
                                 f"in the run ({duration_s:g} s)")
        t_c, _, f = min(candidates, key=lambda c: (c[0], c[1]))
        faults = [x.at(t_c + x.trigger.delay_s) if x.fid == f.fid else x for x in faults]
        faults = resolve_after(faults)
    left = [f for f in faults if f.trigger.at_s is None]
    if left:
        raise FaultSpecError(f"fault {left[0].fid} ({left[0].spec()}): its trigger cannot be "
                             "resolved")
    return faults
