# SPDX-License-Identifier: Apache-2.0
"""Helpers of the flight tests: a system with a stand-in mission manager, world faults, the
downlink and the world's events, failure dumps."""

from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import yaml

from ima.campaign.systems import drop_partition

ROOT = Path(__file__).resolve().parents[2]
PILOTS = ROOT / "sim" / "pilots"

# The single-node flight's bounds in light turbulence (judged on the truth over the holds);
# a redundant system must fly within the same ones.
LIGHT_BOUNDS = {"alt_err_ft_rms": 12, "alt_err_ft_max": 60, "airspeed_err_kt_rms": 6,
                "airspeed_err_kt_max": 20, "heading_err_deg_rms": 3, "heading_err_deg_max": 12}


def within(summary: dict, bounds: dict) -> list[str]:
    """The bounds a summary breaks (an unjudged value breaks its bound too)."""
    return [f"{k} = {summary.get(k)} > {v}" for k, v in bounds.items()
            if summary.get(k) is None or summary[k] > v]


def scratch_system(dest: Path, edit, nodes: int = 1) -> Path:
    """A system model in `dest` that is the shipped RPAS application (config/applications/
    rpas.yaml) changed by `edit(application_dict)`, on `nodes` nodes: the model is the only
    place a test changes a deployment. Returns the system file."""
    app = yaml.safe_load((ROOT / "config" / "applications" / "rpas.yaml").read_text())
    for section, key in (("can", "dbc"), ("dds", "config")):
        app["channels"][section][key] = str(ROOT / "config" / "applications" /
                                            app["channels"][section][key])
    edit(app)
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "application.yaml").write_text(yaml.safe_dump(app, sort_keys=False))
    system = {"include": "application.yaml", "system": "scratch",
              "nodes": [{"name": f"node{k}", "index": k} for k in range(1, nodes + 1)]}
    path = dest / "system.yaml"
    path.write_text(yaml.safe_dump(system, sort_keys=False))
    return path


def mission_system(dest: Path, feed_args: list[str]) -> Path:
    """The one-node system with a stand-in mission manager (partition mission_feed) writing
    fixed MISSION targets to nav_fcs, in place of the mission manager."""
    def add_feed(app: dict) -> None:
        drop_partition(app, "mission_manager")
        app["partitions"].append({
            "name": "mission_feed", "criticality": "LEVEL_C", "personality": "apex-c",
            "executable": "mission_feed", "arguments": list(feed_args), "period_s": 0.05,
            "processes": [{"name": "feed", "period_s": 0.05, "stack": 65536, "priority": 10}],
            "ports": [{"name": "MISSION_OUT", "direction": "source", "kind": "sampling",
                       "size": 56, "refresh_s": 0.5, "message": "rpas_mission_msg_t"}],
            "memory": [{"type": "DATA", "size": 0x2000000, "access": "READ_WRITE"}]})
        app["schedule"]["windows"].append(
            {"partition": "mission_feed", "start_s": 0.03, "duration_s": 0.005})
        app["channels"]["intra_node"].append(
            {"name": "mission", "from": "mission_feed.MISSION_OUT",
             "to": ["nav_fcs.MISSION_IN", "fdr.MISSION_IN"]})
    return scratch_system(dest, add_feed)


def dump(f) -> str:
    """What a failing assertion shows: the summary without the long lists."""
    s = {k: v for k, v in f.summary.items() if k not in ("hm_event_list",)}
    return json.dumps(s, indent=1)


def host_stalls(run_dir, targets: frozenset = frozenset()) -> list[dict]:
    """The SKE's CPU-budget overruns in the run's node traces, and in those of its golden run
    (RUN_DIR/golden, a run with faults judged against it), but for the (node, partition)
    pairs in `targets` (the ones a fault overruns on purpose). The partitions of these flights
    use a tiny part of their budgets (io some 20 µs of CPU per 5 ms window); one that still
    overran was stalled in the kernel on the host's account (direct reclaim, a preempted
    virtual CPU), not by anything under test. A run with one is flown again, once."""
    run_dir = Path(run_dir)
    out = []
    for trace in sorted([*run_dir.glob("node*.jsonl"), *run_dir.glob("golden/node*.jsonl")]):
        with open(trace) as f:
            for line in f:
                if '"kind":"overrun"' in line and '"cause":"cpu_budget"' in line:
                    e = json.loads(line)
                    if (trace.stem, e.get("partition")) not in targets:
                        out.append(dict(e, trace=str(trace.relative_to(run_dir))))
    return out


def fly_unless_host_stalled(fly, run_dir, name: str, targets: frozenset = frozenset()):
    """`fly()`, which flies into run_dir; once more, into a fresh run_dir, if the host stalled a
    partition past its CPU budget (host_stalls, but for `targets`), with a warning that names
    the stall. Returns the last flight's result; a stall in that one is the tests' to judge."""
    result = fly()
    stalls = host_stalls(run_dir, targets)
    if stalls:
        warnings.warn(f"{name}: flown again, the host stalled a partition past its CPU "
                      f"budget: {stalls[0]}", stacklevel=2)
        shutil.rmtree(run_dir)
        result = fly()
    return result


def fault(spec: str, fid: str):
    """A fault in the short form (faultinject.grammar), for LaunchOptions.faults."""
    from faultinject import grammar

    return grammar.parse(spec, fid)


def status_frames(f) -> list[tuple]:
    """(t, mode, fallback, nav flags) of each FCS_STATUS_A frame on the bus."""
    return [(t, str(d["FCS_MODE_A"]), str(d["FCS_FALLBACK_A"]), int(d["FCS_NAV_FLAGS_A"]))
            for t, d in f.can_frames("FCS_STATUS_A")]


def world_events(f, kind: str) -> list[dict]:
    return [e for e in (json.loads(x) for x in (f.run_dir / "world.jsonl").read_text()
                        .splitlines()) if e["kind"] == kind]
