# SPDX-License-Identifier: Apache-2.0
"""Whether each injection happened: the injector's own `fault` event (applied), and the record
of another component that shows its effect (the catalogue's `evidence`), never the injector's
word alone. A fault requested but unconfirmed is reported as such, never as a pass."""

from __future__ import annotations

import bisect
from dataclasses import dataclass

from faultinject.context import Context
from faultinject.plan import Injection
from faultinject.traces import parse_lines, t_ns_of

SENSOR_IDS = {"gps": (0x9100190, 0x9100194), "ahrs": (0x9100320, 0x9100324, 0x9100328),
              "air": (0x91004B0,)}
# the C2 uplink: PILOT_MODE, _TARGETS, _STICK, MISSION_UPLOAD, MISSION_CMD
PILOT_IDS = (0x8B807D0, 0x8B807D4, 0x8B807D8, 0x8B807F8, 0x8B807FC)
ACT_CMD_A = 0x8D80640


@dataclass
class Confirmation:
    fid: str
    node: str | None
    applied_t_ns: int | None  # the injector's first `applied` event
    evidence_t_ns: int | None  # when the other component's record shows it
    evidence: str  # what was found, or why nothing was

    @property
    def confirmed(self) -> bool:
        return self.applied_t_ns is not None and self.evidence_t_ns is not None

    @property
    def t_ns(self) -> int | None:
        """The confirmed injection time: when the fault first acted (for the evidence that
        marks an activation, ACTIVATION: when it first did so)."""
        if not self.confirmed:
            return None
        if self.evidence in ACTIVATION:
            return max(self.applied_t_ns, self.evidence_t_ns)
        return self.applied_t_ns


# Evidence that shows when a dormant fault becomes an error: a wrong value equal to the right
# one (a hard-over where the command already is) is no error until they part.
ACTIVATION = ("command_departs",)
AXES = ("ELEV", "AIL", "RUD", "THR")


def _applied(ctx: Context, inj: Injection) -> tuple[int | None, str]:
    """The injector's first `applied` event for this injection (and its `refused` reason)."""
    refused = ""
    nodes = {n.name for n in ctx.system.nodes}
    for e in ctx.run.fault_events:
        if e.get("fid") != inj.fid:
            continue
        if inj.node is not None and e.get("node") in nodes and e.get("node") != inj.node:
            continue  # a common-mode fault's event of another node
        if e.get("state") == "applied":
            return e["t_ns"], ""
        if e.get("state") == "refused":
            refused = e.get("detail", "refused")
    return None, refused


def _node_index(ctx: Context, node: str | None) -> int | None:
    return next((n.index for n in ctx.system.nodes if n.name == node), None)


def _first(events, t0: int, pred) -> int | None:
    return next((e["t_ns"] for e in events if e["t_ns"] >= t0 and pred(e)), None)


def _frames_differ(ctx: Context, ids: tuple[int, ...], t0: int) -> int | None:
    """The first frame time at which the run's frames of `ids` differ from the golden run's
    (the records compared as bytes first: only from the first that differs are they parsed)."""
    if ctx.golden is None:
        return None
    raw_run, raw_gold = ctx.run.frame_lines(*ids), ctx.golden.frame_lines(*ids)
    i = min(bisect.bisect_left(raw_run, t0, key=t_ns_of),
            bisect.bisect_left(raw_gold, t0, key=t_ns_of))
    while i < len(raw_run) and i < len(raw_gold) and raw_run[i] == raw_gold[i]:
        i += 1
    if i == len(raw_run) == len(raw_gold):
        return None
    run = [(e["t_ns"], e["id"], e["data"]) for e in parse_lines(raw_run[i:]) if e["t_ns"] >= t0]
    gold = [(e["t_ns"], e["id"], e["data"]) for e in parse_lines(raw_gold[i:]) if e["t_ns"] >= t0]
    for a, b in zip(run, gold, strict=False):
        if a != b:
            return min(a[0], b[0])
    if len(run) != len(gold):
        return (run[len(gold)] if len(run) > len(gold) else gold[len(run)])[0]
    return None


def _io_frames_stop(ctx: Context, node: str | None, t0: int) -> int | None:
    """When a frame the node's io sent in the golden run at or after t0 did not reach the wire
    (without a golden run: its last frame, if it stopped sending before the end)."""
    if node is None:
        return None
    name = f"{node}/io"
    mine = [(e["t_ns"], e["id"]) for e in ctx.run.frames_from(name)]
    if ctx.golden is not None:
        sent = {x for x in mine if x[0] >= t0}
        return next((t for t, i in ((e["t_ns"], e["id"]) for e in ctx.golden.frames_from(name)
                                    if e["t_ns"] >= t0)
                     if (t, i) not in sent), None)
    after = [t for t, _ in mine if t >= t0]
    last = ctx.run.last_frame_t_ns()
    end = last if last is not None else 0
    if not mine or (after and after[-1] > end - 200_000_000):
        return None  # still sending near the end
    return max(t0, mine[-1][0])


def check(ctx: Context, inj: Injection) -> Confirmation:
    fc = ctx.fault_class(inj.fault)
    t0 = inj.fault.at_ns
    applied, refused = _applied(ctx, inj)
    if inj.fault.cls in ("node_crash", "node_freeze"):
        kind = "node_kill" if inj.fault.cls == "node_crash" else "node_hang"
        k = _node_index(ctx, inj.node)
        applied = _first(ctx.run.bus_kind(kind, "node_freeze", "node_hang"), t0,
                         lambda e: e.get("killed_node", e.get("node_id", e.get("hung_node"))) == k)
    found: list[tuple[int, str]] = []
    for ev in fc.evidence:
        t = _evidence(ctx, inj, ev, t0)
        if t is not None:
            found.append((t, ev))
    if applied is None:
        why = f"no `applied` event from the injector{': ' + refused if refused else ''}"
        return Confirmation(inj.fid, inj.node, None, min(found)[0] if found else None, why)
    if not found:
        return Confirmation(inj.fid, inj.node, applied, None,
                            f"applied, but no {'/'.join(fc.evidence)} record shows it")
    t, ev = min(found)
    return Confirmation(inj.fid, inj.node, applied, t, ev)


def _evidence(ctx: Context, inj: Injection, kind: str, t0: int) -> int | None:
    node, part = inj.node, inj.fault.target.partition
    if kind == "hm":
        return _first(ctx.run.node_kind(node, "hm") if node else [], t0,
                      lambda e: part is None or e.get("partition") == part)
    if kind == "overrun":
        return _first(ctx.run.node_kind(node, "overrun") if node else [], t0,
                      lambda e: part is None or e.get("partition") == part)
    if kind == "module_reset":
        return _first(ctx.run.node_kind(node, "mode") if node else [], t0,
                      lambda e: e.get("reason") == "module reset")
    if kind in ("port_silent", "port_changed"):
        if ctx.golden is None or node is None:
            return None
        port = inj.fault.target.port
        run = [x for x in ctx.run.port_hashes(node, part).get(port, []) if x[0] >= t0]
        gold = [x for x in ctx.golden.port_hashes(node, part).get(port, []) if x[0] >= t0]
        if kind == "port_silent":
            return gold[len(run)][0] if len(gold) > len(run) else None
        return next((a[0] for a, b in zip(run, gold, strict=False) if a != b), None)
    k = _node_index(ctx, node)
    if kind == "frames_stopped":
        return _io_frames_stop(ctx, node, t0)
    if kind == "frames_changed" and k is not None:
        return _frames_differ(ctx, (ACT_CMD_A + k - 1,), t0)
    if kind == "command_departs" and k is not None:
        return _command_departs(ctx, ACT_CMD_A + k - 1, t0)
    if kind == "can_error":
        return _first(ctx.run.bus_kind("can_error", "error_frame", "bus_off"), t0, lambda e: True)
    if kind == "frames_missing":  # the bus's wire: a frame that never reached it, or a receiver
        return _first(ctx.run.bus_kind("can_drop", "can_rx_drop"), t0,
                      lambda e: e.get("fid") == inj.fid)
    if kind == "frames_duplicated":
        return _first(ctx.run.frames, t0, lambda e: e.get("duplicate") is True)
    if kind == "frames_flood":  # a babbler's frames on the wire
        return _first(ctx.run.frames, t0, lambda e: e.get("fid") == inj.fid)
    if kind == "frames_late":
        return _frames_differ(ctx, tuple({e["id"] for e in ctx.run.frames}), t0)
    if kind == "dds_missing":
        others = [e for n, evs in ctx.run.dds.items() if n != node for e in evs]
        return _first(sorted(others, key=lambda e: e.get("t_ns", 0)), t0,
                      lambda e: e.get("kind") in ("dds_deadline_missed", "xch_peer_missing",
                                                  "dds_peer_lost")
                      and e.get("peer") == node)
    if kind == "sensor_frames":
        return _frames_differ(ctx, tuple(i for ids in SENSOR_IDS.values() for i in ids), t0)
    if kind == "pilot_frames":
        return _frames_differ(ctx, PILOT_IDS, t0)
    if kind == "truth_surface":
        return _truth_differs(ctx, t0, ("elev", "ail", "rud", "thr"))
    if kind == "downlink_mode":
        return _first([{"t_ns": t, **d} for t, _, d in ctx.run.fcs_status], t0,
                      lambda e: e.get("FCS_FALLBACK", 0) != 0 or e.get("FCS_MODE") == 1)
    if kind == "app_report":
        return _first(ctx.run.app_messages(node) if node else [], t0,
                      lambda e: e.get("text", "").startswith(f"fault {inj.fid} "))
    return None


def _command_departs(ctx: Context, can_id: int, t0: int) -> int | None:
    """The first of the node's actuator commands at or after t0 from which the commands depart
    from the golden run's by more than the voter's threshold on some axis for `persist`
    commands in a row (the system model's voting): an error the voter can see, not a brush
    past the threshold for a frame."""
    if ctx.golden is None:
        return None
    thresholds = ctx.system.voting["thresholds"]
    persist = max(1, int(ctx.system.voting.get("persist", 1)))
    gold = {e["t_ns"]: ctx.golden.decode(e) for e in ctx.golden.frames_of(can_id)
            if e["t_ns"] >= t0}
    first, run_len = None, 0
    for e in ctx.run.frames_of(can_id):
        if e["t_ns"] < t0 or e["t_ns"] not in gold:
            continue
        run, want = ctx.run.decode(e), gold[e["t_ns"]]
        departs = False
        for axis in AXES:
            key = next(k for k in run if k.startswith(axis + "_CMD_"))
            if abs(run[key] - want[key]) > float(thresholds[axis.lower()]):
                departs = True
                break
        if not departs:
            first, run_len = None, 0
            continue
        first = e["t_ns"] if first is None else first
        run_len += 1
        if run_len >= persist:
            return first
    return None


def _truth_differs(ctx: Context, t0: int, keys: tuple[str, ...]) -> int | None:
    if ctx.golden is None:
        return None
    for a, b in zip(ctx.run.truth, ctx.golden.truth, strict=False):
        if a["t_ns"] >= t0 and any(a.get(k) != b.get(k) for k in keys):
            return a["t_ns"]
    return None
