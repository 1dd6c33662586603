# SPDX-License-Identifier: Apache-2.0
"""The house's rules, checked on the sources: every source file of the product opens with its
SPDX line and a sentence saying what it is for, none is over 700 lines (tests aside), and
nothing cites a design document the repository does not hold (docs/architecture.md is the
map)."""

from __future__ import annotations

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
COMPONENTS = ("ske", "nodes", "partitions", "health_monitor", "sim", "python/ima")
SOURCE = (".c", ".h", ".cpp", ".py")
MAX_LINES = 700


def _tracked(*folders: str) -> list[Path]:
    out = subprocess.run(["git", "ls-files", "--", *folders], cwd=ROOT, capture_output=True,
                         text=True)
    if out.returncode != 0:  # not a git checkout: every file on disk
        return [p for f in folders for p in (ROOT / f).rglob("*") if p.is_file()]
    return [ROOT / line for line in out.stdout.splitlines() if (ROOT / line).is_file()]


def _is_test(path: Path) -> bool:
    parts = path.relative_to(ROOT).parts
    return any(p in ("test", "tests") for p in parts) or path.name.startswith("test_")


def test_no_source_file_of_a_component_is_over_700_lines() -> None:
    long = []
    for path in _tracked(*COMPONENTS):
        if path.suffix in SOURCE and not _is_test(path):
            n = len(path.read_text(encoding="utf-8", errors="replace").splitlines())
            if n > MAX_LINES:
                long.append(f"{path.relative_to(ROOT)}: {n} lines")
    assert not long, "split these into files of one job each:\n" + "\n".join(long)


def test_every_source_file_opens_with_spdx_and_what_it_is_for() -> None:
    bad = []
    for path in _tracked(*COMPONENTS, "tests", "bench"):
        if path.suffix not in SOURCE:
            continue
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
        head = "\n".join(lines[:3])
        if "SPDX-License-Identifier" not in head:
            bad.append(f"{path.relative_to(ROOT)}: no SPDX line at the top")
        elif len(lines) < 2 or not lines[1].strip().lstrip("#").strip():
            bad.append(f"{path.relative_to(ROOT)}: no sentence saying what it is for")
    assert not bad, "\n".join(bad)


def test_nothing_cites_a_design_document_outside_the_repository() -> None:
    out = subprocess.run(["git", "grep", "-n", "DESIGN\\.md", "--", ".", ":!tests/python/"
                          "test_house_rules.py"], cwd=ROOT, capture_output=True, text=True)
    assert out.stdout == "", "point these at docs/architecture.md:\n" + out.stdout
