# SPDX-License-Identifier: Apache-2.0
"""Judges a launched system: the flight (as `ima fly` does, from the world's truth), plus what
the redundancy did: which replicas the actuators voted out and when, the node membership the
nodes agreed on, the nodes' self-monitor reports, the DDS agents' view."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ima.flight import summary as flight_summary
from ima.flight.summary import read_jsonl, write_summary

MEMBERSHIP_PREFIX = "membership "
MONITOR_PREFIX = "cross-channel monitor: "


def parse_members(text: str) -> list[str]:
    """'membership node1,node3 (lost node2)' -> ['node1', 'node3']."""
    body = text[len(MEMBERSHIP_PREFIX):].split(" (")[0].strip()
    return [m for m in body.split(",") if m]


def node_reports(run_dir: Path, node: str) -> dict[str, list[dict]]:
    """The io partition's membership changes and self-monitor reports in a node's trace."""
    membership, monitor = [], []
    for rec in read_jsonl(run_dir / f"{node}.jsonl", needle="app_message"):
        if rec.get("kind") != "app_message":
            continue
        text = rec.get("text", "")
        if text.startswith(MEMBERSHIP_PREFIX):
            membership.append({"t_s": round(rec["t_ns"] / 1e9, 3), "node": node,
                               "members": parse_members(text)})
        elif text.startswith(MONITOR_PREFIX):
            monitor.append({"t_s": round(rec["t_ns"] / 1e9, 3), "node": node,
                            "text": text[len(MONITOR_PREFIX):]})
    return {"membership": membership, "monitor": monitor}


def voting(run_dir: Path) -> dict[str, Any]:
    """The actuators' voting, from the world's trace."""
    voted_out, changes = [], []
    for rec in read_jsonl(run_dir / "world.jsonl"):
        kind = rec.get("kind")
        if kind == "voted_out":
            voted_out.append({"node": rec.get("node"), "t_s": round(rec["t_ns"] / 1e9, 3),
                              "channel": rec.get("channel"), "reason": rec.get("reason")})
        elif kind == "vote":
            changes.append({k: rec.get(k) for k in ("status", "used")}
                           | {"t_s": round(rec["t_ns"] / 1e9, 3)})
    return {"voted_out": voted_out, "vote_changes": changes,
            "vote_status": changes[-1]["status"] if changes else None}


def _dds_stats(run_dir: Path, node_index: int) -> dict | None:
    return _stats(run_dir / f"dds{node_index}.json")


def _stats(path: Path) -> dict | None:
    try:
        st = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return st if isinstance(st, dict) else None


def refused(run_dir: Path, nodes: list[str]) -> list[dict]:
    """What the run's processes refused, one list from the `refusals` list of every statistics
    file that has one: the bus's (`can_client`), each DDS agent's (`io_client`, ...); each
    entry {"what", "detail"} with `by`, the process that refused it (docs/flight.md)."""
    sources = [("canbus", run_dir / "canbus.json")]
    sources += [(f"{node}/dds", run_dir / f"dds{k}.json") for k, node in enumerate(nodes, 1)]
    out = []
    for by, path in sources:
        for entry in (_stats(path) or {}).get("refusals") or []:
            if isinstance(entry, dict) and isinstance(entry.get("what"), str):
                out.append({"what": entry["what"], "detail": str(entry.get("detail", "")),
                            "by": by})
    return out


def stopped_by(run_dir: Path) -> str | None:
    """Who ended the run before its end: a bus client's name (the world after a crash),
    "launcher" or "signal"; None when it flew to its end."""
    return (_stats(run_dir / "canbus.json") or {}).get("stopped_by")


def dds_refused(dds: dict[str, dict]) -> list[dict]:
    """The summary's `refused` entries of DDS (what: "dds_participant"): each participant of
    the run's domain that is not a node's agent, from the agents' statistics, once, with the
    samples each agent refused from it (keyed as another node than the partition it wrote in,
    docs/security.md)."""
    seen: dict[str, dict] = {}
    for node, st in dds.items():
        for p in st.get("foreign_participants", []):
            seen.setdefault(p["guid"], {"process": p.get("process") or "?",
                                        "pid": p.get("pid"), "refused": {}})
        for r in st.get("refused", []):
            entry = seen.setdefault(r["participant"], {"process": "?", "pid": None,
                                                       "refused": {}})
            key = (r["topic"], r["partition"], r["claimed_node"])
            entry["refused"].setdefault(key, {})[node] = r["samples"]
    out = []
    for guid, e in sorted(seen.items()):
        who = e["process"] + (f" (pid {e['pid']})" if e["pid"] else "")
        detail = f"{who}, participant {guid}, joined the run's DDS domain and is no node's agent"
        parts = []
        for (topic, partition, claimed), by in sorted(e["refused"].items()):
            counts = ", ".join(f"{n} {c}" for n, c in sorted(by.items()))
            parts.append(f"its {topic} keyed as node{claimed} from partition "
                         f"'{partition}' were refused ({counts})")
        detail += ("; " + "; ".join(parts)) if parts else ": none of the agents took its data"
        out.append({"what": "dds_participant", "detail": detail})
    return out


def fault_targets(plan) -> set[tuple[str, str | None]]:
    """(node, partition) a run's faults (its FaultPlan, or None) act on directly; partition
    None: the whole node."""
    if plan is None:
        return set()
    from faultinject.oracles import direct_targets

    return {t for inj in plan.injections for t in direct_targets(inj)}


def summarise(run_dir: Path, pilot: Path, duration_s: float, nodes: list[str],
              killed: dict[str, float], wall_s: float | None = None,
              plot: bool = False, hung: dict[str, float] | None = None,
              fault_targets: set[tuple[str, str | None]] | None = None) -> dict[str, Any]:
    """The run's summary (also written to RUN_DIR/summary.json); `fault_targets`: what the
    run's faults act on (fault_targets(), for host_stalls)."""
    hung = hung or {}
    vote = voting(run_dir)
    events = [(t, f"{k} stopped") for k, t in killed.items()]
    events += [(t, f"{k} hung") for k, t in hung.items()]
    events += [(v["t_s"], f"{v['node']} voted out") for v in vote["voted_out"]]
    summary = flight_summary.summarise(run_dir, pilot, duration_s, wall_s, nodes=len(nodes),
                                       plot=plot, events=sorted(events),
                                       fault_targets=fault_targets)
    summary["nodes"] = list(nodes)
    summary["killed"] = [{"node": k, "t_s": t} for k, t in sorted(killed.items())]
    summary["hung"] = [{"node": k, "t_s": t} for k, t in sorted(hung.items())]
    summary.update(vote)
    views: dict[str, list[str]] = {}
    membership_events, monitor = [], []
    for node in nodes:
        rep = node_reports(run_dir, node)
        membership_events += rep["membership"]
        monitor += rep["monitor"]
        views[node] = rep["membership"][-1]["members"] if rep["membership"] else list(nodes)
    # The membership the live nodes agree on (a killed or hung node's last view is not a vote).
    live_views = {n: v for n, v in views.items() if n not in killed and n not in hung}
    agreed = sorted({tuple(v) for v in live_views.values()})
    summary["membership"] = list(agreed[0]) if len(agreed) == 1 else None
    summary["membership_agreed"] = len(agreed) == 1
    summary["membership_views"] = views
    summary["membership_events"] = sorted(membership_events, key=lambda e: (e["t_s"], e["node"]))
    summary["monitor_reports"] = sorted(monitor, key=lambda e: (e["t_s"], e["node"]))
    dds = {}
    for k, node in enumerate(nodes, start=1):
        st = _dds_stats(run_dir, k)
        if st is not None:
            dds[node] = st
    if dds:
        summary["dds"] = dds
        summary["dds_security"] = _security_mode(run_dir) if any(
            st.get("security") for st in dds.values()) else "off"
    summary["stopped_by"] = stopped_by(run_dir)
    summary["refused"] = refused(run_dir, nodes) + dds_refused(dds)
    write(run_dir, summary)
    return summary


def _security_mode(run_dir: Path) -> str:
    """The DDS Security mode the run's governance document says (ima.dds.security)."""
    from ima.dds import security

    return security.mode_of(run_dir / security.DIR_NAME) or "on"


def write(run_dir: Path, summary: dict) -> None:
    """RUN_DIR/summary.json."""
    write_summary(run_dir, summary)
