# SPDX-License-Identifier: Apache-2.0
"""A run's faults: the options that name them (--fault, --faults, and the older --kill-node,
--hang-node, --test-wrong-output), their triggers resolved (a condition by a run of the
system up to it), and the plan that gives each injector its words (faultinject.plan)."""

from __future__ import annotations

import dataclasses
import shutil
from collections.abc import Callable
from pathlib import Path

from faultinject import grammar
from faultinject.model import Fault, Target, Trigger
from faultinject.plan import Plan, check_target, compile_plan
from faultinject.resolve import resolve
from ima.launch.options import LaunchOptions


def requested(opts: LaunchOptions) -> list[Fault]:
    """Every fault the options ask for, in order, with ids f1, f2, ... where not given."""
    out: list[Fault] = list(opts.faults)
    n = len(out)

    def fid() -> str:
        nonlocal n
        n += 1
        while any(f.fid == f"f{n}" for f in out):
            n += 1
        return f"f{n}"

    for node, t in opts.kill:
        out.append(Fault(fid(), "node_crash", Target(node), Trigger(at_s=t)))
    for node, t in opts.hang:
        out.append(Fault(fid(), "node_freeze", Target(node), Trigger(at_s=t)))
    for node, axis, value, t in opts.wrong_output:
        out.append(Fault(fid(), "wrong_output", Target(node), Trigger(at_s=t),
                         params={"mode": "bias", "axis": axis, "value": value}))
    return grammar.check_ids(out, "the run's faults")


def prepare(opts: LaunchOptions, system, run_dir: Path,
            launch: Callable[..., object]) -> Plan:
    """The faults resolved and compiled. A trigger on a condition is resolved by runs of the
    system with the faults resolved so far (run_dir/resolve-K/, removed after)."""
    faults = requested(opts)
    for f in faults:  # a bad target is refused before any run resolves a condition
        check_target(system, f)
    runs = 0

    def run_once(resolved: list[Fault], until: Callable[[dict], bool]) -> Path:
        nonlocal runs
        runs += 1
        pre = dataclasses.replace(opts, faults=resolved, kill=[], hang=[], wrong_output=[],
                                  run_dir=run_dir / f"resolve-{runs}", judge=False)
        launch(pre, stop_when=until)
        return pre.run_dir

    if any(f.trigger.at_s is None for f in faults):
        faults = resolve(faults, run_once, opts.duration_s)
        for k in range(1, runs):  # the last one is kept: it shows how the condition came
            shutil.rmtree(run_dir / f"resolve-{k}", ignore_errors=True)
    return compile_plan(system, faults, opts.duration_s)
