# SPDX-License-Identifier: Apache-2.0
"""Judges a run with faults against its golden run: each fault confirmed or not, every
oracle's verdict, and one outcome for the run (the FARM record of campaigns: the Fault, its
Activation, the Readouts, the Measures)."""

from __future__ import annotations

import json
from pathlib import Path

from faultinject import detectors, hm_tables, oracles
from faultinject.context import Context
from faultinject.evidence import Confirmation, check
from faultinject.plan import Plan
from faultinject.traces import RunTraces

ORACLES = {"temporal_isolation": oracles.temporal_isolation,
           "data_isolation": oracles.data_isolation, "detection": oracles.detection,
           "hm_action": oracles.hm_action, "degraded_mode": oracles.degraded_mode,
           "envelope": oracles.envelope}
# From the worst: one outcome stands for a run of several faults.
SEVERITY = ("undetected_hazardous", "undetected_benign", "detected_degraded",
            "detected_recovered", "masked", "not_activated")


def _stats(run_dir: Path, node: str) -> dict:
    try:
        return json.loads((run_dir / f"{node}.json").read_text())
    except (OSError, ValueError):
        return {}


def degraded_at_end(ctx: Context) -> list[str]:
    """What the run ends without that the golden run ends with: a replica voted out, a node
    stopped or out of the membership, a partition down, a fallback in force."""
    out = []
    gold_out = {e.get("node") for e in ctx.golden.world_kind("voted_out")} if ctx.golden else set()
    out += [f"{e.get('node')} voted out" for e in ctx.run.world_kind("voted_out")
            if e.get("node") not in gold_out]
    out += [f"{n} stopped" for n in ctx.plan.kills] + [f"{n} frozen" for n in ctx.plan.hangs]
    for node in ctx.node_names:
        if node in ctx.plan.kills or node in ctx.plan.hangs:
            continue
        run = {p["name"]: p.get("state") for p in _stats(ctx.run.run_dir, node).get(
            "partitions", [])}
        gold = {p["name"]: p.get("state") for p in _stats(ctx.golden.run_dir, node).get(
            "partitions", [])} if ctx.golden else {}
        out += [f"{p}@{node} {s}" for p, s in run.items() if s != gold.get(p, s)]
        for e in ctx.run.app_messages(node):
            if e.get("text", "").startswith("membership ") and "(lost " in e["text"]:
                out.append(f"{node}: {e['text']}")
                break
    last = _last_status(ctx.run)
    gold_last = _last_status(ctx.golden) if ctx.golden else {}
    for k, d in last.items():
        g = gold_last.get(k, {})
        if d.get("FCS_FALLBACK") != g.get("FCS_FALLBACK") or d.get("FCS_MODE") != g.get("FCS_MODE"):
            out.append(f"channel {k}: mode {d.get('FCS_MODE')} fallback {d.get('FCS_FALLBACK')} "
                       f"at the end")
            break
    return out


def _hm_of(ctx: Context, f, t_ns: int | None) -> dict | None:
    """The first health-monitor decision on the fault's target after it acted, with what the
    node's tables prescribe for it (computed from the module, faultinject.hm_tables)."""
    if t_ns is None:
        return None
    nodes = ctx.node_names if f.target.node in ("*", "world", "bus") else [f.target.node]
    for node in nodes:
        for e in ctx.run.node_kind(node, "hm"):
            if e["t_ns"] >= t_ns and (f.target.partition is None or
                                      e.get("partition") == f.target.partition):
                tables = hm_tables.read(ctx.run.module(node))
                allowed = hm_tables.expected(tables, e.get("partition"), e.get("state"),
                                             e.get("error"))
                return {"node": node, "t_s": e["t_ns"] / 1e9, "partition": e.get("partition"),
                        "error": e.get("error"), "level": e.get("level"),
                        "action": e.get("action"),
                        "prescribed": sorted(list(x) for x in allowed),
                        "decisions": sum(1 for x in ctx.run.node_kind(node, "hm")
                                         if x.get("partition") == e.get("partition"))}
    return None


def _expectations(fc, redundant: bool) -> dict:
    """What the catalogue expects of a class in this system."""
    return {"detectors": list(fc.detectors(redundant)), "latency_ms": fc.latency_ms,
            "hm_error": fc.hm_error, "mode": fc.mode, "masked": fc.masked if redundant else None,
            "masked_reason": fc.masked_reason if redundant else None,
            "outcomes": list(fc.expected_outcomes(redundant))}


def _outcome(confirmed: bool, detected: bool, degraded: bool, identical: bool,
             env_left: bool) -> str:
    if not confirmed:
        return "not_activated"
    if detected:
        return "detected_degraded" if degraded else "detected_recovered"
    if env_left:
        return "undetected_hazardous"
    if identical or not degraded:
        return "masked" if identical else "undetected_benign"
    return "undetected_benign"


def confirmation(ctx: Context, conf: list[Confirmation]) -> dict:
    """Every injection confirmed by another component's record. One that was not is reported
    as `unconfirmed` (never a pass); it is a violation unless its class may go unactivated in
    this system (the catalogue's outcomes say `not_activated`)."""
    missing = [(inj, c) for inj, c in zip(ctx.plan.injections, conf, strict=True)
               if not c.confirmed]
    text = [c.fid + (f"@{c.node}" if c.node else "") + f": {c.evidence}" for _, c in missing]
    if not missing:
        return {"verdict": "pass", "unconfirmed": []}
    allowed = all("not_activated" in ctx.fault_class(inj.fault).expected_outcomes(
        ctx.redundant) for inj, _ in missing)
    return {"verdict": "unconfirmed" if allowed else "fail", "unconfirmed": text}


def _last_status(traces: RunTraces) -> dict[int, dict]:
    """Each channel's last FCS_MODE and FCS_FALLBACK."""
    out: dict[int, dict] = {}
    for field in ("FCS_MODE", "FCS_FALLBACK"):
        for k, (_times, values) in traces.fcs_field(field).items():
            out.setdefault(k, {})[field] = values[-1]
    return out


_GOLDEN: dict = {}  # the last golden run read by this process: a campaign's runs share them


def golden_traces(golden_dir: Path) -> RunTraces:
    """The golden run's records, kept from one judgement to the next of the same process
    (re-read if the run directory was flown again)."""
    path = Path(golden_dir).resolve()
    try:
        stamp = (path / "truth.jsonl").stat().st_mtime_ns
    except OSError:
        stamp = None
    key = (path, stamp)
    if key not in _GOLDEN:
        _GOLDEN.clear()
        _GOLDEN[key] = RunTraces(path)
    return _GOLDEN[key]


def judge(run_dir: Path, golden_dir: Path | None, plan: Plan, system, duration_s: float,
          run: RunTraces | None = None) -> dict:
    """The `faults`, `oracles` and `outcome` of a run's summary (`run`: the run's records when
    the caller has read some already)."""
    ctx = Context(run=run or RunTraces(run_dir), golden=golden_traces(golden_dir) if golden_dir
                  else None, plan=plan, system=system, duration_s=duration_s)
    conf = [check(ctx, inj) for inj in plan.injections]
    verdicts = {"confirmation": confirmation(ctx, conf)}
    verdicts.update({name: fn(ctx, conf) for name, fn in ORACLES.items()})
    degraded = degraded_at_end(ctx)
    identical = ctx.golden is not None and ctx.run.truth_bytes == ctx.golden.truth_bytes
    env_left = bool(verdicts["envelope"]["left"]) or verdicts["envelope"]["crashed"]
    faults, outcomes = [], []
    for f in plan.faults:
        mine = [(inj, c) for inj, c in zip(plan.injections, conf, strict=True)
                if inj.fid == f.fid]
        t = min((c.t_ns for _, c in mine if c.t_ns is not None), default=None)
        detected = {}
        for inj, c in mine:
            if c.t_ns is not None:
                detected.update(detectors.fired(ctx, inj, c.t_ns))
        confirmed = all(c.confirmed for _, c in mine)
        fc = ctx.fault_class(f)
        outcome = _outcome(confirmed, bool(detected), bool(degraded), identical, env_left)
        expected = fc.expected_outcomes(ctx.redundant)
        outcomes.append(outcome)
        first = min(detected.values(), default=None)
        faults.append({
            "id": f.fid, "spec": f.spec(), "class": f.cls, "layer": fc.layer,
            "requested_t_s": f.trigger.at_s, "applied": confirmed,
            "t_s": None if t is None else t / 1e9,
            "evidence": [{"node": c.node, "evidence": c.evidence,
                          "t_s": None if c.evidence_t_ns is None else c.evidence_t_ns / 1e9}
                         for _, c in mine],
            "detected_by": sorted(detected), "latency_ms": None if first is None or t is None
            else round((first - t) / 1e6, 3),
            "outcome": outcome, "expected_outcomes": list(expected),
            "hm": _hm_of(ctx, f, t), "expected": _expectations(fc, ctx.redundant),
            "known_limit": fc.known_limit["reason"] if fc.known_limit_applies(
                ctx.redundant, f.target.node == "*") else None,
        })
    run_outcome = min(outcomes, key=SEVERITY.index) if outcomes else "not_activated"
    # In a run of several faults the degradation may be another's: a fault whose class expects
    # it to be detected and recovered from may end degraded when another fault of the run
    # degraded the system, as that one's class allows.
    degraders = [f["id"] for f in faults if f["outcome"] == "detected_degraded"
                 and "detected_degraded" in f["expected_outcomes"]]
    for f in faults:
        others = [g for g in degraders if g != f["id"]]
        if f["outcome"] == "detected_degraded" and others and \
                "detected_degraded" not in f["expected_outcomes"] and \
                "detected_recovered" in f["expected_outcomes"]:
            f["degraded_by"] = others
    bad = [f["id"] for f in faults if f["outcome"] not in f["expected_outcomes"]
           and not f.get("degraded_by")]
    verdicts["outcome"] = {"verdict": "fail" if bad else "pass", "outcome": run_outcome,
                           "unexpected": bad}
    violations = sorted(k for k, v in verdicts.items() if v.get("verdict") == "fail")
    known = [f["id"] for f in faults if f["known_limit"]]
    return {"faults": faults, "oracles": verdicts, "outcome": run_outcome,
            "oracle_violations": violations, "degraded": degraded,
            "known_limit": known, "truth_identical": identical}
