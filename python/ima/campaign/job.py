# SPDX-License-Identifier: Apache-2.0
"""One run of a campaign, as a worker flies it (in a process of this machine or on a Dask
worker: its arguments are plain data): the launch with the run's faults, flown again once if
the host stalled a partition that was not a target, judged against its golden run, and
turned into one FARM record (Fault, Activation, Readouts, Measures)."""

from __future__ import annotations

import functools
import shutil
import time
from pathlib import Path

from ima.errors import ImaError
from ima.launch.options import LaunchOptions

# Not in the deterministic part of a record: what the machine, not the run, decides.
VOLATILE = ("wall_s", "flight_wall_s", "provenance", "refly", "worker", "run_dir", "recording")


def system_for(campaign_dir: Path, workload: dict, system: str) -> Path:
    """The system a workload flies: the campaign's, or its derived one with the stand-in
    mission feed (written by the runner into campaign_dir/systems/)."""
    if workload.get("mission_feed"):
        return campaign_dir / "systems" / f"{workload['name']}.yaml"
    return Path(system)


def options(campaign: dict, run: dict, run_dir: Path, faults: list) -> LaunchOptions:
    w = campaign["workloads"][run["workload"]]
    return LaunchOptions(
        system=system_for(Path(campaign["dir"]), w, campaign["system"]),
        duration_s=campaign["duration_s"], seed=run["seed"], pilot=Path(w["pilot"]),
        turbulence=w["turbulence"], wind_kt=w["wind_kt"], run_dir=run_dir, kind="campaign",
        mission=Path(w["mission"]) if w.get("mission") else None,
        realtime=bool(run.get("realtime")),
        faults=faults, judge=False, port_hashes=True, test_switches=list(
            campaign.get("test_switches") or []))


def host_stalls(traces, targets: set[tuple[str, str | None]]) -> list[dict]:
    """CPU-budget overruns of partitions that are not targets of a fault (see
    ima.flight.summary.host_stalls)."""
    from ima.flight.summary import host_stalls as stalls

    return stalls([dict(e, node=node) for node in traces.nodes
                   for e in traces.node_kind(node, "overrun") if e.get("cause") == "cpu_budget"],
                  targets)


@functools.lru_cache(maxsize=4)
def _system(path: str, mtime_ns: int):
    from ima.deploy import load_system

    return load_system(Path(path))


def system_of(path: Path):
    """The system model, read once per worker (again if the file changed)."""
    try:
        stamp = path.stat().st_mtime_ns
    except OSError:
        stamp = -1  # load_system says what is wrong with it
    return _system(str(path), stamp)


def run_one(campaign: dict, run: dict, run_dir: Path | None = None) -> dict:
    """Flies and judges one run (into run_dir, by default the campaign folder's
    runs/RUN_ID); returns its record (results.jsonl)."""
    from faultinject import grammar
    from faultinject.judge import judge
    from faultinject.traces import RunTraces
    from ima import provenance
    from ima.launch import run as launch_run
    from ima.launch import summary as launch_summary

    t0 = time.monotonic()
    cdir = Path(campaign["dir"])
    run_dir = Path(run_dir) if run_dir is not None else cdir / "runs" / run["run_id"]
    golden = cdir / "golden" / campaign["golden_of"][run["run_id"]]
    faults = [grammar.parse(s, f"f{k}") for k, s in enumerate(run["faults"], start=1)]
    refly = 0
    flight_wall = 0.0
    while True:
        shutil.rmtree(run_dir, ignore_errors=True)
        opts = options(campaign, run, run_dir, faults)
        try:
            result = launch_run.launch(opts, system=system_of(Path(opts.system)))
        except ImaError as exc:
            # A run that could not be flown (a condition that never came, a process that
            # would not start) is a failed run of the campaign, not the campaign's end.
            return _unflown(campaign, run, run_dir, faults, exc, t0)
        flight_wall += result.wall_s
        if result.interrupted:
            raise KeyboardInterrupt(f"{run['run_id']} interrupted")
        targets = launch_summary.fault_targets(result.plan)
        traces = RunTraces(run_dir)  # read once: the stalls, the judgement, the HM
        stalls = host_stalls(traces, targets)
        if not stalls or refly >= 2:
            break
        refly += 1
    system = system_of(Path(opts.system))
    failed = {k: v for k, v in result.returncodes.items()
              if v not in (0, None) and k.split("/")[0] not in {**result.killed, **result.hung}}
    j = judge(run_dir, golden, result.plan, system, campaign["duration_s"], run=traces)
    measures = {"outcome": j["outcome"],
                "oracles": {k: v.get("verdict") for k, v in j["oracles"].items()},
                "oracle_violations": j["oracle_violations"], "known_limit": j["known_limit"]}
    if failed:
        measures["oracle_violations"] = sorted(set(measures["oracle_violations"]) | {"processes"})
        measures["failed_processes"] = failed
    record = {
        "run_id": run["run_id"], "group": run["group"], "classes": run["classes"],
        "workload": run["workload"], "seed": run["seed"], "weight": run["weight"],
        "fault": {"specs": run["faults"],
                  "faults": [{"id": f["id"], "class": f["class"], "spec": f["spec"],
                              "requested_t_s": f["requested_t_s"]} for f in j["faults"]]},
        "activation": {"confirmed": all(f["applied"] for f in j["faults"]),
                       "faults": [{"id": f["id"], "applied": f["applied"], "t_s": f["t_s"],
                                   "evidence": f["evidence"]} for f in j["faults"]]},
        "readouts": {"faults": [{"id": f["id"], "detected_by": f["detected_by"],
                                 "latency_ms": f["latency_ms"], "outcome": f["outcome"],
                                 "expected_outcomes": f["expected_outcomes"]}
                                for f in j["faults"]],
                     "degraded": j["degraded"], "truth_identical": j["truth_identical"],
                     "hm": [{k: e.get(k) for k in ("t_ns", "partition", "error", "level",
                                                    "action")}
                            for n in result.nodes for e in traces.node_kind(n, "hm")][:20]},
        "measures": measures,
        "oracles": j["oracles"],
        "refly": refly, "wall_s": round(time.monotonic() - t0, 2),
        "flight_wall_s": round(flight_wall, 2),
        "provenance": provenance.provenance(campaign.get("argv")),
    }
    keep = campaign.get("keep_all") or measures["oracle_violations"] or \
        measures["outcome"] == "undetected_hazardous"
    record["run_dir"] = str(run_dir) if keep else None
    if keep:
        record["recording"] = _record(run_dir)
    else:
        shutil.rmtree(run_dir, ignore_errors=True)
    return record


def _record(run_dir: Path) -> str | None:
    """run.mcap of a run the campaign keeps (docs/recording.md); None if it failed."""
    from ima.recording import write

    try:
        return write.record(run_dir)["file"]
    except ImaError:
        return None


def _unflown(campaign: dict, run: dict, run_dir: Path, faults: list, exc: Exception,
             t0: float) -> dict:
    """The record of a run that could not be flown: no fault activated, the run a failure
    (its oracle_violations name `run`), its folder kept."""
    from ima import provenance

    return {
        "run_id": run["run_id"], "group": run["group"], "classes": run["classes"],
        "workload": run["workload"], "seed": run["seed"], "weight": run["weight"],
        "fault": {"specs": run["faults"],
                  "faults": [{"id": f.fid, "class": f.cls, "spec": f.spec(),
                              "requested_t_s": f.trigger.at_s} for f in faults]},
        "activation": {"confirmed": False,
                       "faults": [{"id": f.fid, "applied": False, "t_s": None, "evidence": []}
                                  for f in faults]},
        "readouts": {"faults": [{"id": f.fid, "detected_by": [], "latency_ms": None,
                                 "outcome": "not_activated", "expected_outcomes": []}
                                for f in faults],
                     "degraded": [], "truth_identical": False, "hm": []},
        "measures": {"outcome": "not_activated", "oracles": {}, "oracle_violations": ["run"],
                     "known_limit": [], "error": str(exc)},
        "oracles": {},
        "refly": 0, "wall_s": round(time.monotonic() - t0, 2), "flight_wall_s": 0.0,
        "provenance": provenance.provenance(campaign.get("argv")),
        "run_dir": str(run_dir),
    }


def deterministic(record: dict) -> dict:
    """The record without its volatile fields: what two runs of one campaign agree on."""
    return {k: v for k, v in record.items() if k not in VOLATILE}
