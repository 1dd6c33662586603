# SPDX-License-Identifier: Apache-2.0
"""Line and branch coverage of the C code (`ima test --coverage`): the instrumented build tree,
gcovr's per-file summary, and its figures per component."""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

# What is measured: the product's C code, without its tests and benchmark programs.
MEASURED = ("ske", "health_monitor", "nodes")
EXCLUDED = (r"(.+/)?tests?/", r"nodes/bench/", r"nodes/dds/xch_bench\.c$")
# The components reported, the three above and these parts of them.
PARTS = ("ske/src", "ske/apex/src", "ske/abi/src", "health_monitor/src", "nodes/src", "nodes/dds")

REPORT = "coverage.json"  # in the coverage build tree
FILES_REPORT = "coverage-files.json"  # gcovr's own per-file summary, next to it


def configure_commands(root: Path, build: Path) -> list[list[str]]:
    """Configure and build the instrumented tree (-O0, so that lines and branches are the
    source's own)."""
    configure = ["cmake", "-S", str(root), "-B", str(build), "-G", "Ninja",
                 "-DIMA_COVERAGE=ON", "-DCMAKE_BUILD_TYPE=Debug"]
    return [configure, ["cmake", "--build", str(build)]]


def reset_counters(build: Path) -> int:
    """Deletes the counters of earlier runs; returns how many files it removed."""
    n = 0
    for f in build.rglob("*.gcda"):
        f.unlink()
        n += 1
    return n


def gcovr_command(python: str, root: Path, build: Path) -> list[str]:
    """gcovr over the build tree's counters, the measured folders only, writing its per-file
    summary (JSON) to the build tree."""
    base = re.escape(str(root.resolve())) + "/"
    cmd = [python, "-m", "gcovr", "--root", str(root), "--object-directory", str(build),
           "--gcov-executable", "gcov", "-j", "2", "--merge-mode-functions", "separate",
           "--json-summary", str(build / FILES_REPORT), "--json-summary-pretty",
           "--txt", str(build / "coverage-files.txt")]
    for folder in MEASURED:
        cmd += ["--filter", base + folder + "/"]
    for pattern in EXCLUDED:
        cmd += ["--exclude", base + pattern]
    # The tests' own objects are not searched either (their counters are of no interest).
    cmd += ["--exclude-directories", re.escape(str(build.resolve())) + r"/(.+/)?tests?(/|$)"]
    return cmd + [str(build)]


def _percent(covered: int, total: int) -> float:
    return round(100.0 * covered / total, 1) if total else 100.0


def _figures(files: Iterable[Mapping]) -> dict:
    lc = lt = bc = bt = 0
    for f in files:
        lc += f["line_covered"]
        lt += f["line_total"]
        bc += f["branch_covered"]
        bt += f["branch_total"]
    return {"line_percent": _percent(lc, lt), "branch_percent": _percent(bc, bt),
            "lines_covered": lc, "lines_total": lt,
            "branches_covered": bc, "branches_total": bt}


def components(summary: Mapping) -> dict[str, dict]:
    """Figures per component from gcovr's JSON summary: each measured folder, then its parts.
    Every component has line_percent and branch_percent, and the counts they come from."""
    files = summary["files"]

    def under(prefix: str) -> list[Mapping]:
        return [f for f in files if f["filename"].startswith(prefix + "/")]

    out = {name: _figures(under(name)) for name in MEASURED}
    out.update({name: _figures(under(name)) for name in PARTS})
    return out


def table(figures: Mapping[str, Mapping]) -> str:
    """The figures as a text table, one component a row."""
    rows = [f"{'component':<20} {'lines':>7} {'branches':>9}   {'lines':>13} {'branches':>13}"]
    for name, f in figures.items():
        rows.append(f"{name:<20} {f['line_percent']:>6.1f}% {f['branch_percent']:>8.1f}%   "
                    f"{f['lines_covered']:>6}/{f['lines_total']:<6} "
                    f"{f['branches_covered']:>6}/{f['branches_total']:<6}")
    return "\n".join(rows)


def write_report(build: Path) -> tuple[Path, dict[str, dict]]:
    """Reads gcovr's summary from the build tree, writes coverage.json next to it."""
    summary = json.loads((build / FILES_REPORT).read_text())
    figures = components(summary)
    path = build / REPORT
    path.write_text(json.dumps(figures, indent=2) + "\n")
    return path, figures
