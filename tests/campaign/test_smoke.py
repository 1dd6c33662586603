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
