# SPDX-License-Identifier: Apache-2.0
"""The product's detectors, as the run's records show them firing: the health monitor, the
actuators' voter, the replicas' self-monitors, the node membership, the DDS deadlines, the
navigation's source monitoring, the flight control's fallbacks and modes, the CAN error
handling. Each gives the first time it fired at or after an instant, for a target."""

from __future__ import annotations

import bisect

from faultinject.context import Context
from faultinject.plan import Injection
from faultinject.traces import fcs_choices


def _first(events, t0: int, pred) -> int | None:
    return next((e["t_ns"] for e in events if e["t_ns"] >= t0 and pred(e)), None)


def _nodes_of(ctx: Context, inj: Injection) -> list[str]:
    """The nodes whose detectors speak of this injection: its own, or all for the world/bus."""
    return [inj.node] if inj.node in ctx.node_names else ctx.node_names


def hm(ctx: Context, inj: Injection, t0: int) -> int | None:
    times = [_first(ctx.run.node_kind(n, "hm"), t0, lambda e: True) for n in _nodes_of(ctx, inj)]
    return min((t for t in times if t is not None), default=None)


def vote_out(ctx: Context, inj: Injection, t0: int) -> int | None:
    mine = inj.node in ctx.node_names
    return _first(ctx.run.world_kind("voted_out"), t0,
                  lambda e: not mine or e.get("node") == inj.node)


def self_monitor(ctx: Context, inj: Injection, t0: int) -> int | None:
    mine = inj.node in ctx.node_names

    def says(node: str, e: dict) -> bool:
        text = e.get("text", "")
        if not text.startswith("cross-channel monitor:"):
            return False
        return not mine or (node == inj.node and "own output" in text) or f"{inj.node} " in text

    times = [_first(ctx.run.app_messages(n), t0, lambda e, n=n: says(n, e))
             for n in ctx.node_names]
    return min((t for t in times if t is not None), default=None)


def membership(ctx: Context, inj: Injection, t0: int) -> int | None:
    mine = inj.node in ctx.node_names

    def lost(e: dict) -> bool:
        text = e.get("text", "")
        if not text.startswith("membership "):
            return False
        gone = text.partition("(lost ")[2].rstrip(")").split(",")
        return not mine or inj.node in gone

    times = [_first(ctx.run.app_messages(n), t0, lost) for n in ctx.node_names if n != inj.node]
    return min((t for t in times if t is not None), default=None)


def dds_deadline(ctx: Context, inj: Injection, t0: int) -> int | None:
    mine = inj.node in ctx.node_names
    times = []
    for node, events in ctx.run.dds.items():
        if node == inj.node:
            continue
        times.append(_first([e for e in events if "t_ns" in e], t0,
                            lambda e: e.get("kind") in ("dds_deadline_missed", "dds_peer_lost")
                            and (not mine or e.get("peer") == inj.node)))
    return min((t for t in times if t is not None), default=None)


def _status_change(ctx: Context, t0: int, field: str, changed) -> int | None:
    """The first heartbeat at or after t0 whose `field` changed (changed(expected, now)) from
    what the same replica reported in the golden run at that time (the workload's own mode
    changes are no detection); without a golden run, from its value before t0."""
    first = None
    if ctx.golden is not None:
        gold = ctx.golden.fcs_field(field)
        for k, (run_times, run_values) in ctx.run.fcs_field(field).items():
            if k not in gold:
                continue
            times, values = gold[k]
            for i in range(bisect.bisect_left(run_times, t0), len(run_times)):
                j = bisect.bisect_right(times, run_times[i]) - 1
                if j >= 0 and changed(values[j], run_values[i]):
                    found = run_times[i]
                    first = found if first is None else min(first, found)
                    break
        return first
    before: dict[int, int] = {}
    for t, k, d in ctx.run.fcs_status:
        v = d.get(field)
        if t < t0:
            before[k] = v
        elif k in before and changed(before[k], v):
            return t
    return None


def nav_flags(ctx: Context, inj: Injection, t0: int) -> int | None:
    return _status_change(ctx, t0, "FCS_NAV_FLAGS", lambda a, b: b & a != a)


def fallback(ctx: Context, inj: Injection, t0: int) -> int | None:
    return _status_change(ctx, t0, "FCS_FALLBACK", lambda a, b: b != a and b != 0)


def mode(ctx: Context, inj: Injection, t0: int) -> int | None:
    return _status_change(ctx, t0, "FCS_MODE", lambda a, b: b != a)


def bus_error(ctx: Context, inj: Injection, t0: int) -> int | None:
    return _first(ctx.run.bus_kind("can_error", "error_frame", "bus_off"), t0, lambda e: True)


DETECTORS = {"hm": hm, "vote_out": vote_out, "self_monitor": self_monitor,
             "membership": membership, "dds_deadline": dds_deadline, "nav_flags": nav_flags,
             "fallback": fallback, "mode": mode, "bus_error": bus_error}


def fired(ctx: Context, inj: Injection, t0: int) -> dict[str, int]:
    """Every detector that fired at or after t0, with its first time."""
    out = {}
    for name, fn in DETECTORS.items():
        t = fn(ctx, inj, t0)
        if t is not None:
            out[name] = t
    return out


def reached_mode(ctx: Context, t0: int, want_mode: str,
                 want_fallback: str | list[str] | None) -> int | None:
    """The first heartbeat at or after t0 that reports the mode (and fallback) wanted."""
    modes, fallbacks = fcs_choices("FCS_MODE"), fcs_choices("FCS_FALLBACK")
    wanted = None if want_fallback is None else (
        [want_fallback] if isinstance(want_fallback, str) else want_fallback)
    fb = ctx.run.fcs_field("FCS_FALLBACK")
    first = None
    for k, (times, values) in ctx.run.fcs_field("FCS_MODE").items():
        for i in range(bisect.bisect_left(times, t0), len(times)):
            if modes.get(values[i]) == want_mode and (
                    wanted is None or fallbacks.get(fb[k][1][i]) in wanted):
                first = times[i] if first is None else min(first, times[i])
                break
    return first
