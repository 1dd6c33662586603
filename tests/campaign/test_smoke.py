# SPDX-License-Identifier: Apache-2.0
"""The smoke campaign (config/campaigns/smoke.yaml): every fault class of the catalogue
injected on short triplex flights, each confirmed by another component's record, judged by
every oracle without a violation, and no undetected hazardous outcome outside the catalogue's
known limits."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from faultinject import catalogue

ROOT = Path(__file__).resolve().parents[2]


def test_every_class_is_injected_confirmed_and_judged(tmp_path):
    out = tmp_path / "smoke"
    p = subprocess.run([sys.executable, "-m", "ima", "campaign",
                        str(ROOT / "config" / "campaigns" / "smoke.yaml"), "--out", str(out),
                        "-j", "2", "--json"], capture_output=True, text=True, cwd=ROOT,
                       timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    report = json.loads(p.stdout)
    records = [json.loads(x) for x in (out / "results.jsonl").read_text().splitlines()]
    assert len(records) == report["runs"] == report["runs_planned"]
    # every class, each confirmed by the evidence of another component
    assert {c["class"] for c in report["classes"]} == set(catalogue.load())
    unconfirmed = [(r["run_id"], r["oracles"]["confirmation"]) for r in records
                   if not r["activation"]["confirmed"]]
    assert not unconfirmed, unconfirmed
    for c in report["classes"]:
        assert c["activated"] == c["injected"] >= 1, c
    # every oracle judged every run, and none disagrees with the catalogue
    bad = [(r["run_id"], {k: v for k, v in r["oracles"].items()
                          if isinstance(v, dict) and v.get("verdict") == "fail"})
           for r in records if r["measures"]["oracle_violations"]]
    assert report["oracle_violations"] == [] and not bad, json.dumps(bad)[:4000]
    assert report["undetected_hazardous"] == []
    for r in records:
        assert set(r["oracles"]) == {"confirmation", "temporal_isolation", "data_isolation",
                                     "detection", "hm_action", "degraded_mode", "envelope",
                                     "outcome"}, r["run_id"]
    # the mission manager flying a real plan, lost on one node and on all: the flight control
    # holds (MISSION_STALE) where it is lost; a single holding replica is voted out
    plan = {r["run_id"]: r for r in records if r["workload"] == "plan"}
    assert len(plan) == 3, sorted(plan)
    for r in plan.values():
        mode = r["oracles"]["degraded_mode"]
        assert mode["verdict"] == "pass" and mode["faults"], (r["run_id"], mode)
        assert all(f["expected"]["fallback"] == "MISSION_STALE" for f in mode["faults"])
    one = next(r for rid, r in plan.items() if "partition_crash" in rid and "node2" in rid)
    assert "node2 voted out" in one["readouts"]["degraded"], one["readouts"]
    every = next(r for rid, r in plan.items() if "partition_crash" in rid and "node" not in
                 rid.split("mission-manager")[1].split("-plan")[0])
    assert not any("voted out" in d for d in every["readouts"]["degraded"]), every["readouts"]
