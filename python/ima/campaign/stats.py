# SPDX-License-Identifier: Apache-2.0
"""A campaign's statistics: per fault class the outcomes, the coverage with its exact 95%
Clopper–Pearson interval, the detection latencies; over all classes a stratified coverage
(each class weighted by the campaign's weights)."""

from __future__ import annotations

import math
import statistics
from collections import Counter, defaultdict

from scipy.stats import beta, norm

COVERED = ("masked", "detected_recovered", "detected_degraded")
OUTCOMES = ("not_activated", "masked", "detected_recovered", "detected_degraded",
            "undetected_benign", "undetected_hazardous")


def clopper_pearson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """The exact two-sided interval of a binomial proportion k/n (Clopper and Pearson, 1934),
    from the beta distribution's quantiles. (With no failure in n runs the one-sided 95 %
    lower bound is 0.05^(1/n): n = 299 bounds coverage at 0.99.)"""
    if n == 0:
        return (0.0, 1.0)
    a = (1 - level) / 2
    lo = 0.0 if k == 0 else float(beta.ppf(a, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1 - a, k + 1, n - k))
    return (lo, hi)


def _pct(values: list[float], q: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, max(0, math.ceil(q * len(s)) - 1))]


def latency(values: list[float]) -> dict | None:
    if not values:
        return None
    return {"n": len(values), "min": round(min(values), 3),
            "median": round(statistics.median(values), 3), "p95": round(_pct(values, 0.95), 3),
            "max": round(max(values), 3)}


def per_class(records: list[dict]) -> list[dict]:
    """One row per fault class (a run of several faults counts under each of its faults'
    classes, with that fault's own outcome)."""
    rows: dict[str, dict] = {}
    lat: dict[str, list[float]] = defaultdict(list)
    weights: dict[str, float] = {}
    for r in records:
        for f, act in zip(r["readouts"]["faults"], r["activation"]["faults"], strict=True):
            cls = next(x["class"] for x in r["fault"]["faults"] if x["id"] == f["id"])
            row = rows.setdefault(cls, {"class": cls, "injected": 0, "activated": 0,
                                        "outcomes": Counter(), "violations": 0,
                                        "known_limit": 0})
            weights[cls] = max(weights.get(cls, 0), float(r.get("weight", 1.0)))
            row["injected"] += 1
            row["activated"] += 1 if act["applied"] else 0
            row["outcomes"][f["outcome"]] += 1
            if r["measures"]["oracle_violations"]:
                row["violations"] += 1
            if f["id"] in r["measures"].get("known_limit", []):
                row["known_limit"] += 1
            if f.get("latency_ms") is not None:
                lat[cls].append(f["latency_ms"])
    out = []
    for cls in sorted(rows):
        row = rows[cls]
        n = row["activated"]
        k = sum(row["outcomes"][o] for o in COVERED)
        lo, hi = clopper_pearson(k, n)
        out.append({**row, "outcomes": {o: row["outcomes"][o] for o in OUTCOMES},
                    "covered": k, "coverage": None if n == 0 else round(k / n, 4),
                    "coverage_ci95": [round(lo, 4), round(hi, 4)],
                    "latency_ms": latency(lat[cls]), "weight": weights[cls]})
    return out


def stratified(rows: list[dict]) -> dict:
    """Σ w_c p_c / Σ w_c over the classes with activated runs, with a normal-approximation
    95 % interval from the strata's variances (p(1-p)/n, with p nudged off 0 and 1 by the
    Agresti–Coull correction so that a stratum without failures still counts)."""
    strata = [r for r in rows if r["activated"] > 0]
    if not strata:
        return {"coverage": None, "ci95": None, "classes": 0}
    w = sum(r["weight"] for r in strata)
    est = sum(r["weight"] * r["covered"] / r["activated"] for r in strata) / w
    var = 0.0
    for r in strata:
        n = r["activated"]
        p = (r["covered"] + 2) / (n + 4)
        var += (r["weight"] / w) ** 2 * p * (1 - p) / (n + 4)
    z = float(norm.ppf(0.975))
    half = z * math.sqrt(var)
    return {"coverage": round(est, 4), "ci95": [round(max(0.0, est - half), 4),
                                               round(min(1.0, est + half), 4)],
            "classes": len(strata), "method": "stratified, weights from the campaign; normal "
            "approximation of the strata's Agresti–Coull variances"}
