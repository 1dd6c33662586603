# SPDX-License-Identifier: Apache-2.0
"""The oracles: each judges one property of a run against its golden run (the same system,
workload and seed without the faults), from the run's records, never from what a component
says of itself. Each gives {"verdict": "pass" | "fail" | "n/a", ...its findings}."""

from __future__ import annotations

from faultinject import detectors, hm_tables
from faultinject.context import Context
from faultinject.evidence import Confirmation
from faultinject.plan import Injection
from faultinject.traces import before

# The safe envelope, judged on the truth (docs/fault-injection.md).
ENVELOPE = {"bank_deg": 60.0, "pitch_up_deg": 25.0, "pitch_down_deg": -20.0,
            "airspeed_min_kt": 55.0, "airspeed_max_kt": 160.0, "agl_min_ft": 200.0}
# How far a masked fault's flight may depart from the golden run's when the catalogue says
# `tracking` (the truth cannot be bit-identical, and says why).
TRACKING = {"alt_ft": 100.0, "airspeed_kt": 15.0, "heading_deg": 15.0}
# The health monitor's errors that say a partition did not get its time: what another
# partition's fault must never cause. (An error a partition reports of its data, such as a
# replica's self-monitor seeing its output voted out, is detection, not interference.)
TIMING_ERRORS = ("WINDOW_OVERRUN", "DEADLINE_MISSED")
# Real-time runs: how far a partition's CPU time (measured on the host) may be from the golden
# run's (a part of it, plus some per emulated second: the host's own noise), and the bound on
# the p99 of its windows' start lateness (docs/fault-injection.md).
REALTIME_TOLERANCE = {"cpu_rel": 0.5, "cpu_abs_ms_per_s": 0.2, "late_p99_ms": 2.0}


def direct_targets(inj: Injection) -> set[tuple[str, str | None]]:
    """(node, partition) the fault acts on directly; partition None: every one of the node."""
    f = inj.fault
    if f.target.partition is not None:
        return {(inj.node, f.target.partition)}
    if f.cls in ("node_crash", "node_freeze", "module_reset"):
        return {(inj.node, None)}
    return set()


def _excluded(ctx: Context, node: str, partition: str) -> bool:
    return any((n, p) in ((node, partition), (node, None))
               for inj in ctx.plan.injections for n, p in direct_targets(inj))


def _timing_events(ctx: Context, node: str, partition: str) -> list[dict]:
    """The partition's overruns and timing errors the golden run does not have."""
    found = []
    for kind in ("overrun", "hm"):
        def timing(e, kind=kind):
            return e.get("partition") == partition and (
                kind == "overrun" or e.get("error") in TIMING_ERRORS)
        extra = [e for e in ctx.run.node_kind(node, kind) if timing(e)]
        if len(extra) > len([e for e in ctx.golden.node_kind(node, kind) if timing(e)]):
            found.append({"node": node, "partition": partition, kind: extra[0]})
    return found


def _p99(values: list[int]) -> int:
    v = sorted(values)
    return v[min(len(v) - 1, int(0.99 * len(v)))] if v else 0


def temporal_isolation(ctx: Context, conf: list[Confirmation]) -> dict:
    """Every partition but the targets gets each of its windows at its planned start, yields
    at the same time as in the golden run (the same work: its releases and time-outs), and has
    no overrun nor timing error (TIMING_ERRORS) the golden run has not. In real time, where
    no two runs yield at the same instants, it is judged on what the host measures instead:
    each partition's CPU time within REALTIME_TOLERANCE of the golden run's, and the p99 of
    its windows' start lateness within its bound."""
    if ctx.golden is None:
        return {"verdict": "n/a", "why": "no golden run"}
    realtime = ctx.run.realtime and ctx.golden.realtime
    findings, checked, measured, limits = [], 0, [], []
    # In real time the modules share the host's CPUs: with fewer CPUs than modules, a faulty
    # partition that burns its whole budget stretches its own window in wall time, and its
    # module's next windows start late. That is the host, not the partitioning: a known limit
    # there; lateness in any other module stays a violation.
    faulty_nodes = {n for inj in ctx.plan.injections for n, _ in direct_targets(inj)}
    oversubscribed = ctx.run.host_cpus is not None and ctx.run.host_cpus < len(ctx.node_names)
    for node in ctx.node_names:
        for p in ctx.system.partitions:
            if _excluded(ctx, node, p.name):
                continue
            checked += 1
            findings += _timing_events(ctx, node, p.name)
            if realtime:
                m = _realtime_check(ctx, node, p.name)
                measured.append(m)
                if m["verdict"] == "fail" and m["exceeded"] == ["window-start lateness"] and \
                        node in faulty_nodes and oversubscribed:
                    m["verdict"] = "known_limit"
                    m["why"] = (f"window-start lateness in the faulty partition's module: a "
                                f"window that uses its whole CPU budget takes longer on a host "
                                f"with fewer CPUs ({ctx.run.host_cpus}) than modules "
                                f"({len(ctx.node_names)})")
                    limits.append(m)
                elif m["verdict"] == "fail":
                    findings.append(m)
                continue
            if ctx.run.window_lines(node, p.name) == ctx.golden.window_lines(node, p.name):
                continue  # the same records, byte for byte
            run, gold = ctx.run.windows(node, p.name), ctx.golden.windows(node, p.name)
            if run != gold:
                diff = next((i for i, (a, b) in enumerate(zip(run, gold, strict=False))
                             if a != b), min(len(run), len(gold)))
                got = run[diff] if diff < len(run) else None
                want = gold[diff] if diff < len(gold) else None
                findings.append({"node": node, "partition": p.name, "window": diff,
                                 "run": got, "golden": want})
    out = {"verdict": "fail" if findings else "pass", "partitions_checked": checked,
           "time": "realtime" if realtime else "emulated", "violations": findings[:10]}
    if realtime:
        out["tolerance"] = REALTIME_TOLERANCE
        out["measured"] = measured
        out["known_limit"] = limits
    return out


def _realtime_check(ctx: Context, node: str, partition: str) -> dict:
    tol = REALTIME_TOLERANCE
    cpu, gold_cpu = ctx.run.cpu_ns(node, partition), ctx.golden.cpu_ns(node, partition)
    late = _p99(ctx.run.window_lateness(node, partition))
    m = {"node": node, "partition": partition, "late_p99_ms": round(late / 1e6, 3)}
    bad = []
    if late > tol["late_p99_ms"] * 1e6:
        bad.append("window-start lateness")
    if cpu is not None and gold_cpu is not None:
        allowed = tol["cpu_rel"] * gold_cpu + tol["cpu_abs_ms_per_s"] * 1e6 * ctx.duration_s
        m.update(cpu_ms=round(cpu / 1e6, 3), golden_cpu_ms=round(gold_cpu / 1e6, 3),
                 cpu_allowed_ms=round(allowed / 1e6, 3))
        if abs(cpu - gold_cpu) > allowed:
            bad.append("CPU time")
    m["verdict"] = "fail" if bad else "pass"
    if bad:
        m["exceeded"] = bad
        m["why"] = ", ".join(bad) + " beyond the tolerance"
    return m


def _downstream(ctx: Context, origins: set[tuple[str, str | None]]) -> set[tuple[str, str]]:
    """(node, partition) reachable from the origins in the system's channel graph: the
    intra-node channels, the CAN bus between the partitions that use it (and the world, which
    closes the loop), DDS between the same partition of every node."""
    s = ctx.system
    can_parts = {p for traffic in s.can_traffic.values() for p in traffic}
    dds_parts = {t["partition"] for t in s.dds_topics}
    every = {(n, p.name) for n in ctx.node_names for p in s.partitions}
    seen: set = set()
    todo = [("world", None)] if not origins else list(origins)
    while todo:
        node, part = todo.pop()
        if (node, part) in seen:
            continue
        seen.add((node, part))
        if node == "world":
            todo += [(n, p) for n, p in every if p in can_parts]
            continue
        if part is None:
            todo += [(node, p.name) for p in s.partitions]
            continue
        for ch in s.channels:
            if ch.source.partition == part:
                todo += [(node, d.partition) for d in ch.destinations]
        if part in can_parts:
            todo += [(n, p) for n, p in every if p in can_parts] + [("world", None)]
        if part in dds_parts:
            todo += [(n, part) for n in ctx.node_names]
    return {x for x in seen if x[0] != "world" and x[1] is not None}


def _truth_divergence(ctx: Context) -> int | None:
    if ctx.run.truth_bytes == ctx.golden.truth_bytes:
        return None
    for a, b in zip(ctx.run.truth, ctx.golden.truth, strict=False):
        if a != b:
            return a["t_ns"]
    return None


def data_isolation(ctx: Context, conf: list[Confirmation]) -> dict:
    """Before the first fault acts, every source port writes what it wrote in the golden run;
    a partition not downstream of any target in the channel graph does so up to the first
    divergence of the truth (after which the physical loop carries the fault everywhere)."""
    if ctx.golden is None:
        return {"verdict": "n/a", "why": "no golden run"}
    if not any(ctx.run.port_hash_partitions(n) for n in ctx.node_names):
        return {"verdict": "n/a", "why": "the run traced no port hashes"}
    # when the first fault acted: confirmed, else as its injector says, else as requested
    t_first = min((c.t_ns if c.t_ns is not None else c.applied_t_ns
                   if c.applied_t_ns is not None else inj.fault.at_ns
                   for inj, c in zip(ctx.plan.injections, conf, strict=True)), default=None)
    stopped = set(ctx.plan.kills) | set(ctx.plan.hangs)
    origins = set()
    for inj in ctx.plan.injections:
        origins |= direct_targets(inj) or ({(inj.node, "io")} if inj.node in ctx.node_names
                                     else {("world", None)})
    downstream = _downstream(ctx, origins)
    t_div = _truth_divergence(ctx)
    findings, compared = [], 0
    for node in ctx.node_names:
        for part in ctx.run.port_hash_partitions(node):
            free = (node, part) not in downstream
            limit = t_div if free else t_first
            if limit is None:
                limit = 1 << 62
            # the partition's records before the limit, as bytes: the same records mean the
            # same messages on every port (the usual case, decided without parsing them)
            a = before(ctx.run.port_hash_lines(node, part), limit)
            b = before(ctx.golden.port_hash_lines(node, part), limit)
            if node in stopped:  # a node killed or frozen loses the trace it had not written
                b = b[:len(a)]
            if a == b:
                compared += len(b)
                continue
            gold = ctx.golden.port_hashes(node, part)
            for port, run_seq in ctx.run.port_hashes(node, part).items():
                ra = [x for x in run_seq if x[0] < limit]
                rb = [x for x in gold.get(port, []) if x[0] < limit]
                if node in stopped:
                    rb = rb[:len(ra)]
                compared += len(rb)
                if ra != rb:
                    at = next((x[0] for x, y in zip(ra, rb, strict=False) if x != y), limit)
                    findings.append({"node": node, "partition": part, "port": port,
                                     "t_s": at / 1e9, "downstream": not free})
    return {"verdict": "fail" if findings else "pass", "messages_compared": compared,
            "not_downstream": sorted(f"{p}@{n}" for n, p in
                                     {(n, p.name) for n in ctx.node_names
                                      for p in ctx.system.partitions} - downstream),
            "truth_diverges_s": None if t_div is None else t_div / 1e9,
            "violations": findings[:10]}


def detection(ctx: Context, conf: list[Confirmation]) -> dict:
    """Per fault: the detectors the catalogue expects fired, within its latency bound from the
    confirmed injection, and the target node's health monitor recorded the class's error
    (`hm_error`) within it; and every detector that fired at all."""
    per_fault, ok = [], True
    for inj, c in zip(ctx.plan.injections, conf, strict=True):
        fc = ctx.fault_class(inj.fault)
        want = fc.detectors(ctx.redundant)
        if c.t_ns is None:
            per_fault.append({"fault": inj.fid, "node": inj.node, "verdict": "n/a",
                              "why": "not confirmed"})
            continue
        fired = detectors.fired(ctx, inj, c.t_ns)
        latency = {k: (t - c.t_ns) / 1e6 for k, t in fired.items()}
        if want == ("none",):
            verdict = "pass"
        else:
            good = [k for k in want if k in latency and latency[k] <= fc.latency_ms]
            verdict = "pass" if good else "fail"
        first = min(latency.values()) if latency else None
        entry = {"fault": inj.fid, "node": inj.node, "expected": list(want),
                 "bound_ms": fc.latency_ms,
                 "fired_ms": {k: round(v, 3) for k, v in latency.items()},
                 "latency_ms": None if first is None else round(first, 3)}
        if fc.hm_error and inj.node in ctx.node_names and {"hm", "self_monitor"} & set(want):
            # the health monitor of the target's node records the error the class is
            t_err = _hm_error_at(ctx, inj, c.t_ns, fc.hm_error)
            entry["hm_error"] = {"expected": fc.hm_error, "ms": None if t_err is None
                                 else round((t_err - c.t_ns) / 1e6, 3)}
            if t_err is None or (t_err - c.t_ns) / 1e6 > fc.latency_ms:
                verdict = "fail"
        ok = ok and verdict != "fail"
        per_fault.append(dict(entry, verdict=verdict))
    return {"verdict": "pass" if ok else "fail", "faults": per_fault}


def _hm_error_at(ctx: Context, inj: Injection, t0: int, error: str) -> int | None:
    part = inj.fault.target.partition
    return next((e["t_ns"] for e in ctx.run.node_kind(inj.node, "hm")
                 if e["t_ns"] >= t0 and e.get("error") == error
                 and (part is None or e.get("partition") == part)), None)


def hm_action(ctx: Context, conf: list[Confirmation]) -> dict:
    """Every health-monitor decision of the run is one the node's module tables prescribe,
    computed here from the module XML (faultinject.hm_tables)."""
    findings, checked = [], 0
    for node in ctx.node_names:
        try:
            tables = hm_tables.read(ctx.run.module(node))
        except (OSError, ValueError) as exc:
            return {"verdict": "fail", "why": f"cannot read {node}'s module: {exc}"}
        for e in ctx.run.node_kind(node, "hm"):
            checked += 1
            allowed = hm_tables.expected(tables, e.get("partition"), e.get("state"),
                                         e.get("error"))
            got = (e.get("level"), e.get("action"))
            if got not in allowed:
                findings.append({"node": node, "t_s": e["t_ns"] / 1e9,
                                 "partition": e.get("partition"), "error": e.get("error"),
                                 "state": e.get("state"), "applied": list(got),
                                 "tables": sorted(list(x) for x in allowed)})
    return {"verdict": "fail" if findings else "pass", "decisions_checked": checked,
            "violations": findings[:10]}


def degraded_mode(ctx: Context, conf: list[Confirmation]) -> dict:
    """The mode (and fallback) the catalogue expects the flight control to reach, reached on
    the downlink within the class's bound."""
    per_fault, ok = [], True
    for inj, c in zip(ctx.plan.injections, conf, strict=True):
        want = ctx.fault_class(inj.fault).mode
        if not want or c.t_ns is None:
            continue
        t = detectors.reached_mode(ctx, c.t_ns, want["mode"], want.get("fallback"))
        bound = float(want.get("within_ms", ctx.fault_class(inj.fault).latency_ms))
        good = t is not None and (t - c.t_ns) / 1e6 <= bound
        ok = ok and good
        per_fault.append({"fault": inj.fid, "expected": want, "bound_ms": bound,
                          "reached_ms": None if t is None else round((t - c.t_ns) / 1e6, 3),
                          "verdict": "pass" if good else "fail"})
    if not per_fault:
        return {"verdict": "n/a", "why": "no fault of the run expects a degraded mode"}
    return {"verdict": "pass" if ok else "fail", "faults": per_fault}


def envelope_findings(ctx: Context) -> dict:
    """Where the truth left the safe envelope, and whether the aircraft crashed."""
    worst: dict = {}
    out = []
    for r in ctx.run.truth:
        checks = (("bank_deg", abs(r.get("roll_deg", 0)) > ENVELOPE["bank_deg"]),
                  ("pitch_deg", not ENVELOPE["pitch_down_deg"] <= r.get("pitch_deg", 0)
                   <= ENVELOPE["pitch_up_deg"]),
                  ("airspeed_kt", not ENVELOPE["airspeed_min_kt"] <= r.get("airspeed_kt", 100)
                   <= ENVELOPE["airspeed_max_kt"]),
                  ("agl_ft", r.get("agl_ft", 1e9) < ENVELOPE["agl_min_ft"]))
        for name, bad in checks:
            if bad and name not in worst:
                worst[name] = r["t_ns"] / 1e9
                out.append({"limit": name, "t_s": r["t_ns"] / 1e9})
    crashed = any(e.get("kind") == "crash" for e in ctx.run.world)
    return {"left": out, "crashed": crashed}


def tracking(ctx: Context) -> dict:
    """The largest departures of the run's truth from the golden run's."""
    d = {"alt_ft": 0.0, "airspeed_kt": 0.0, "heading_deg": 0.0}
    for a, b in zip(ctx.run.truth, ctx.golden.truth, strict=False):
        d["alt_ft"] = max(d["alt_ft"], abs(a.get("alt_ft", 0) - b.get("alt_ft", 0)))
        d["airspeed_kt"] = max(d["airspeed_kt"], abs(a.get("airspeed_kt", 0) -
                                                     b.get("airspeed_kt", 0)))
        h = (a.get("heading_deg", 0) - b.get("heading_deg", 0) + 180) % 360 - 180
        d["heading_deg"] = max(d["heading_deg"], abs(h))
    return {k: round(v, 2) for k, v in d.items()}


def envelope(ctx: Context, conf: list[Confirmation]) -> dict:
    """The aircraft stays in its safe envelope (a class whose known limit is declared may leave
    it: that is its outcome, not a violation); a fault the catalogue says is masked leaves the
    truth bit-identical to the golden run, or within the tracking bounds where it says why
    not."""
    found = envelope_findings(ctx)
    left = bool(found["left"]) or found["crashed"]
    limits = [inj.fid for inj in ctx.plan.injections
              if ctx.fault_class(inj.fault).known_limit_applies(
                  ctx.redundant, inj.fault.target.node == "*")]
    result = {"left": found["left"], "crashed": found["crashed"], "known_limit": limits}
    verdict = "fail" if left and not limits else "pass"
    if ctx.golden is not None and ctx.redundant and len(ctx.plan.faults) == 1:
        f = ctx.plan.faults[0]
        masked = ctx.fault_class(f).masked
        single = f.target.node not in ("*", "world", "bus")
        identical = ctx.run.truth_bytes == ctx.golden.truth_bytes
        result["truth_identical"] = identical
        dev = tracking(ctx)
        result["tracking"] = dev
        if single and masked == "bit_identical" and not identical:
            verdict = "fail"
            result["why"] = "a masked single-replica fault must leave the truth bit-identical"
        elif single and masked == "tracking" and any(dev[k] > TRACKING[k] for k in TRACKING):
            verdict = "fail"
            result["why"] = f"beyond the tracking bounds {TRACKING}"
    result["verdict"] = verdict
    return result
