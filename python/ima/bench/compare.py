# SPDX-License-Identifier: Apache-2.0
"""`ima bench compare`: one benchmark of this checkout against another checkout of the product
(the previous main, built), back to back and alternating, each run pinned to the same CPU, so
that the machine's drift weighs on both sides alike. Reports both sides' runs and, per figure,
the ratio of each pair (this checkout over the other, oriented so that > 1 is better) and the
median of those ratios."""

from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import time
from pathlib import Path

from ima import paths
from ima.errors import ImaError

# The figures compared per benchmark, and whether more is better. Each run is pinned to one
# CPU (taskset), so a benchmark's floating figures are pinned ones too and its aggregate flies
# one flight: `speedup` and `window_switch_us_median` are the pinned figures here.
FIGURES = {
    "ske": {"window_switch_us_median": False, "major_frames_per_s": True,
            "sampling_rw_ns_median": False},
    "flight": {"speedup": True, "peak_rss_mb": False},
    "triplex": {"speedup": True, "peak_rss_mb": False, "dds_latency_us_median": False},
}


def _run(checkout: Path, target: str, cpu: int | None, extra: list[str]) -> dict:
    cmd = [str(checkout / "ima"), "bench", target, "--json", *extra]
    if cpu is not None:
        if shutil.which("taskset") is None:
            raise ImaError("taskset (util-linux) is needed to pin the runs to a CPU")
        cmd = ["taskset", "-c", str(cpu), *cmd]
    env = {k: v for k, v in os.environ.items()
           if k not in ("IMA_ROOT", "IMA_BUILD_DIR", "IMA_PARTITION_PATH", "VIRTUAL_ENV")}
    done = subprocess.run(cmd, capture_output=True, text=True, cwd=checkout, env=env)
    if done.returncode != 0:
        raise ImaError(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()[-500:]}")
    text = done.stdout.strip()
    for candidate in (text, text.splitlines()[-1] if text else ""):  # whole, or its last line
        try:
            return json.loads(candidate)
        except ValueError:
            continue
    raise ImaError(f"{' '.join(cmd)} printed no JSON: {done.stdout[-300:]!r}")


def compare(base: Path, target: str, pairs: int = 5, cpu: int | None = 0,
            extra: list[str] | None = None, progress=None) -> dict:
    """`pairs` runs of each side, alternating (base first in odd pairs, this checkout first in
    even ones); returns both sides' figures and the per-pair ratios with their median."""
    if target not in FIGURES:
        raise ImaError(f"cannot compare '{target}': one of {', '.join(FIGURES)}")
    here = paths.repo_root()
    base = base.resolve()
    if not (base / "ima").is_file():
        raise ImaError(f"{base}: not a checkout of the product (no ./ima)")
    runs: dict[str, list[dict]] = {"this": [], "base": []}
    for k in range(pairs):
        order = [("base", base), ("this", here)] if k % 2 == 0 else [("this", here), ("base", base)]
        for side, checkout in order:
            if progress:
                progress(f"pair {k + 1}/{pairs}: {side}")
            t0 = time.monotonic()
            result = _run(checkout, target, cpu, extra or [])
            result["bench_wall_s"] = round(time.monotonic() - t0, 2)
            runs[side].append(result)
    figures = {}
    for name, more_is_better in FIGURES[target].items():
        a = [r.get(name) for r in runs["this"]]
        b = [r.get(name) for r in runs["base"]]
        if any(x is None for x in a + b) or any(x == 0 for x in a + b):
            figures[name] = {"this": a, "base": b, "ratios": None, "median_ratio": None}
            continue
        ratios = [(x / y if more_is_better else y / x) for x, y in zip(a, b, strict=True)]
        figures[name] = {"this": a, "base": b, "ratios": [round(r, 3) for r in ratios],
                         "median_ratio": round(statistics.median(ratios), 3)}
    return {"target": target, "pairs": pairs, "cpu": cpu, "this": str(here), "base": str(base),
            "figures": figures, "runs": runs}


def run(base: Path, target: str, pairs: int, cpu: int | None, json_out: bool) -> int:
    from rich.console import Console

    console = Console(stderr=True)
    with console.status(f"{target}: this checkout against {base}") as status:
        result = compare(base, target, pairs, cpu, progress=lambda t: status.update(t))
    if json_out:
        print(json.dumps(result))
        return 0
    out = Console()
    out.print(f"{target}, {pairs} alternating pairs"
              + (f", pinned to CPU {cpu}" if cpu is not None else "") + f"; base {base}")
    for name, f in result["figures"].items():
        out.print(f"  {name:28} this {f['this']}  base {f['base']}  median ratio "
                  f"{f['median_ratio']} (> 1: this is better)")
    return 0


