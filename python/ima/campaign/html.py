# SPDX-License-Identifier: Apache-2.0
"""report.html: one self-contained page (the plots inline as PNG) with the outcomes per fault
class, the detection-latency distribution per class, the coverage per class with its exact
95 % interval, the stratified overall estimate, the known limits and the failing runs."""

from __future__ import annotations

import base64
import io
from html import escape

COLOURS = {"not_activated": "#bbbbbb", "masked": "#4c9f70", "detected_recovered": "#74a9cf",
           "detected_degraded": "#2b6ea8", "undetected_benign": "#f0b34a",
           "undetected_hazardous": "#c8443b"}


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    return base64.b64encode(buf.getvalue()).decode()


def _plots(report: dict) -> dict[str, str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = report["classes"]
    names = [r["class"] for r in rows]
    out = {}
    fig, ax = plt.subplots(figsize=(10, max(3, 0.3 * len(rows) + 1)))
    left = [0] * len(rows)
    for outcome, colour in COLOURS.items():
        vals = [r["outcomes"][outcome] for r in rows]
        ax.barh(names, vals, left=left, color=colour, label=outcome.replace("_", " "))
        left = [a + b for a, b in zip(left, vals, strict=True)]
    ax.invert_yaxis()
    ax.set_xlabel("runs")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("Outcomes per fault class")
    out["outcomes"] = _png(fig)
    plt.close(fig)

    cov = [(r["class"], r["coverage"], r["coverage_ci95"]) for r in rows
           if r["coverage"] is not None]
    if cov:
        fig, ax = plt.subplots(figsize=(10, max(3, 0.3 * len(cov) + 1)))
        for i, (_, c, (lo, hi)) in enumerate(cov):
            ax.plot([lo, hi], [i, i], color="#2b6ea8")
            ax.plot([c], [i], "o", color="#2b6ea8")
        ax.set_yticks(range(len(cov)), [c[0] for c in cov])
        ax.invert_yaxis()
        ax.set_xlim(-0.02, 1.02)
        ax.set_xlabel("coverage, with its exact 95 % Clopper–Pearson interval")
        ax.set_title("Coverage per fault class")
        out["coverage"] = _png(fig)
        plt.close(fig)

    lats = [(r["class"], r["latency_ms"]) for r in rows if r["latency_ms"]]
    if lats:
        fig, ax = plt.subplots(figsize=(10, max(3, 0.3 * len(lats) + 1)))
        for i, (_, lat) in enumerate(lats):
            ax.plot([lat["min"], lat["max"]], [i, i], color="#999999")
            ax.plot([lat["median"]], [i], "o", color="#2b6ea8")
            ax.plot([lat["p95"]], [i], "|", color="#c8443b", markersize=12)
        ax.set_yticks(range(len(lats)), [c for c, _ in lats])
        ax.invert_yaxis()
        ax.set_xscale("symlog", linthresh=10)
        ax.set_xlabel("detection latency (ms): min–max, median (dot), p95 (bar)")
        ax.set_title("Detection latency per fault class")
        out["latency"] = _png(fig)
        plt.close(fig)
    return out


def _table(headers: list[str], rows: list[list]) -> str:
    head = "".join(f"<th>{escape(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def render(report: dict, records: list[dict]) -> str:
    plots = _plots(report)
    rows = []
    for r in report["classes"]:
        o = r["outcomes"]
        lat = r["latency_ms"]
        rows.append([r["class"], r["injected"], r["activated"], o["masked"],
                     o["detected_recovered"], o["detected_degraded"], o["undetected_benign"],
                     o["undetected_hazardous"],
                     "-" if r["coverage"] is None else f"{r['coverage']:.3f}",
                     f"[{r['coverage_ci95'][0]:.3f}, {r['coverage_ci95'][1]:.3f}]",
                     "-" if lat is None else f"{lat['median']:.1f} / {lat['p95']:.1f} / "
                     f"{lat['max']:.1f}", r["violations"]])
    classes = _table(["class", "runs", "activated", "masked", "detected, recovered",
                      "detected, degraded", "undetected, benign", "undetected, hazardous",
                      "coverage", "95 % CI", "latency ms median / p95 / max", "violations"],
                     rows)
    limits = _table(["class", "known limit (declared in the catalogue)"],
                    [[c, why] for c, whys in report["known_limits"].items() for why in whys])
    failing = [[r["run_id"], ", ".join(r["fault"]["specs"]), r["measures"]["outcome"],
                ", ".join(r["measures"]["oracle_violations"]) or "-", r.get("run_dir") or "-"]
               for r in records if r["measures"]["oracle_violations"]
               or (r["measures"]["outcome"] == "undetected_hazardous"
                   and not r["measures"].get("known_limit"))]
    ov = report["overall"]
    overall = "no activated run" if ov["coverage"] is None else (
        f"{ov['coverage']:.3f}, 95 % interval [{ov['ci95'][0]:.3f}, {ov['ci95'][1]:.3f}] "
        f"over {ov['classes']} classes ({escape(ov['method'])})")
    prov = report["provenance"]
    imgs = "".join(f'<img alt="{k}" src="data:image/png;base64,{v}">' for k, v in plots.items())
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>Campaign {escape(report['campaign'])}</title>
<style>
body {{ font-family: sans-serif; margin: 2em; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; font-size: 90%; }}
th, td {{ border: 1px solid #ccc; padding: 3px 8px; text-align: right; }}
td:first-child, th:first-child {{ text-align: left; }}
img {{ display: block; max-width: 100%; margin: 1em 0; }}
</style></head><body>
<h1>Fault campaign {escape(report['campaign'])}</h1>
<p>{report['runs']} runs ({report['runs_planned']} planned), {report['injections']} injections,
{report['class_count']} fault classes; oracle violations: {len(report['oracle_violations'])};
undetected hazardous outside the known limits: {len(report['undetected_hazardous'])};
runs flown again after a host stall: {report['refly']}.</p>
<p>Overall coverage (stratified): {overall}.</p>
<h2>Per fault class</h2>
<p>Coverage = (masked + detected, recovered + detected, degraded) / activated; undetected but
benign runs are counted apart.</p>
{classes}
{imgs}
<h2>Known limits</h2>
{limits}
<h2>Failing runs</h2>
{_table(["run", "faults", "outcome", "oracle violations", "run directory"], failing)
 if failing else "<p>None.</p>"}
<h2>Provenance</h2>
<p>commit {escape(str(prov.get('commit')))}{' (with local changes)' if prov.get('dirty') else ''};
JSBSim {escape(str(prov.get('jsbsim')))}; Cyclone DDS {escape(str(prov.get('cyclonedds')))};
command: <code>{escape(' '.join(prov.get('command') or []))}</code></p>
</body></html>
"""
