# SPDX-License-Identifier: Apache-2.0
"""A campaign's report from its results: report.json (documented, versioned fields),
junit.xml (one test case per run; a failure is an oracle violation or an undetected
hazardous outcome outside the declared known limits), report.html, and the terminal
summary."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

from faultinject import catalogue
from ima import provenance
from ima.campaign import stats

REPORT_VERSION = 1


def build(name: str, records: list[dict], runs_planned: int, argv: list[str] | None = None) -> dict:
    rows = stats.per_class(records)
    hazardous = [r["run_id"] for r in records
                 if r["measures"]["outcome"] == "undetected_hazardous"
                 and not r["measures"].get("known_limit")]
    violations = [{"run_id": r["run_id"], "oracles": r["measures"]["oracle_violations"]}
                  for r in records if r["measures"]["oracle_violations"]]
    limits = {c.name: c.known_limits() for c in catalogue.load().values() if c.known_limits()}
    return {
        "report_version": REPORT_VERSION,
        "campaign": name,
        "runs": len(records),
        "runs_planned": runs_planned,
        "injections": sum(len(r["fault"]["faults"]) for r in records),
        "classes": rows,
        "class_count": len(rows),
        "overall": stats.stratified(rows),
        "oracle_violations": violations,
        "undetected_hazardous": hazardous,
        "known_limits": {c: limits[c] for c in sorted(limits) if any(r["class"] == c
                                                                     for r in rows)},
        "host_limits": host_limits(records),
        "refly": sum(r.get("refly", 0) for r in records),
        "wall_s": round(sum(r.get("wall_s", 0) for r in records), 1),
        "provenance": provenance.provenance(argv),
    }


def host_limits(records: list[dict]) -> list[dict]:
    """Real-time runs whose faulty module's windows started late because the host has fewer
    CPUs than modules (the temporal isolation oracle's known_limit): not violations."""
    out = []
    for r in records:
        ti = (r.get("oracles") or {}).get("temporal_isolation") or {}
        out += [{"run_id": r["run_id"], "node": m["node"], "partition": m["partition"],
                 "late_p99_ms": m["late_p99_ms"]} for m in ti.get("known_limit", [])]
    return out


def failure_of(record: dict) -> str | None:
    m = record["measures"]
    if m.get("error"):
        return "the run could not be flown: " + m["error"]
    if m["oracle_violations"]:
        return "oracle violation: " + ", ".join(m["oracle_violations"])
    if m["outcome"] == "undetected_hazardous" and not m.get("known_limit"):
        return "undetected hazardous outcome outside the catalogue's known limits"
    return None


def junit(records: list[dict], name: str) -> str:
    suite = ET.Element("testsuite", name=f"campaign {name}", tests=str(len(records)),
                       failures=str(sum(1 for r in records if failure_of(r))))
    for r in records:
        case = ET.SubElement(suite, "testcase", classname=r["group"], name=r["run_id"],
                             time=f"{r.get('wall_s', 0):.2f}")
        why = failure_of(r)
        if why:
            fail = ET.SubElement(case, "failure", message=why)
            fail.text = json.dumps({"faults": r["fault"]["specs"],
                                    "oracles": r["measures"]["oracles"],
                                    "outcome": r["measures"]["outcome"],
                                    "run_dir": r.get("run_dir")}, indent=1)
        out = ET.SubElement(case, "system-out")
        out.text = f"outcome {r['measures']['outcome']}; faults {', '.join(r['fault']['specs'])}"
    ET.indent(suite)
    body = ET.tostring(suite, encoding="unicode")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + body + "\n"


def write(out: Path, report: dict, records: list[dict]) -> list[Path]:
    from ima.campaign import html

    paths = [out / "report.json", out / "junit.xml", out / "report.html"]
    paths[0].write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
    paths[1].write_text(junit(records, report["campaign"]), encoding="utf-8")
    paths[2].write_text(html.render(report, records), encoding="utf-8")
    return paths


def print_summary(report: dict, console) -> None:
    from rich.table import Table

    console.rule(f"Campaign {report['campaign']}: {report['runs']} runs, "
                 f"{report['injections']} injections, {report['class_count']} classes")
    t = Table(show_edge=False)
    for col in ("class", "runs", "activated", "masked", "det.-rec.", "det.-degr.", "undet.-ben.",
                "undet.-haz.", "coverage [95% CI]", "latency ms (median/p95)"):
        t.add_column(col, justify="right" if col != "class" else "left")
    for r in report["classes"]:
        o = r["outcomes"]
        cov = "-" if r["coverage"] is None else \
            f"{r['coverage']:.2f} [{r['coverage_ci95'][0]:.2f}, {r['coverage_ci95'][1]:.2f}]"
        lat = r["latency_ms"]
        t.add_row(r["class"] + (" *" if r.get("known_limit") else ""),
                  str(r["injected"]), str(r["activated"]), str(o["masked"]),
                  str(o["detected_recovered"]), str(o["detected_degraded"]),
                  str(o["undetected_benign"]), str(o["undetected_hazardous"]), cov,
                  "-" if lat is None else f"{lat['median']:.0f} / {lat['p95']:.0f}")
    console.print(t)
    ov = report["overall"]
    if ov["coverage"] is not None:
        console.print(f"Overall (stratified): coverage {ov['coverage']:.3f}, 95% interval "
                      f"[{ov['ci95'][0]:.3f}, {ov['ci95'][1]:.3f}] over {ov['classes']} classes")
    if any(r.get("known_limit") for r in report["classes"]):
        console.print("* some of its runs met a known limit of the design, declared in the "
                      "catalogue")
    if report.get("host_limits"):
        runs = sorted({h["run_id"] for h in report["host_limits"]})
        console.print(f"Real-time windows late in the faulty module on a host with fewer CPUs "
                      f"than modules (a known limit): {len(runs)} runs ({', '.join(runs[:5])}"
                      f"{' ...' if len(runs) > 5 else ''})")
    bad = report["oracle_violations"]
    console.print(f"Oracle violations: {len(bad)}" + (f" ({', '.join(v['run_id'] for v in bad[:5])}"
                                                       f"{' ...' if len(bad) > 5 else ''})"
                                                       if bad else ""))
    haz = report["undetected_hazardous"]
    console.print(f"Undetected hazardous outside the known limits: {len(haz)}")
