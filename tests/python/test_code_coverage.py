# SPDX-License-Identifier: Apache-2.0
"""Tests of `ima test --coverage`'s figures: components from gcovr's per-file summary, the
table, coverage.json, and the gcovr command (measured folders in, tests out)."""

from __future__ import annotations

import json
from pathlib import Path

from ima import code_coverage


def _file(name: str, lines: tuple[int, int], branches: tuple[int, int]) -> dict:
    return {"filename": name, "line_covered": lines[0], "line_total": lines[1],
            "branch_covered": branches[0], "branch_total": branches[1]}


SUMMARY = {"files": [
    _file("ske/src/spawn.c", (90, 100), (40, 50)),
    _file("ske/apex/src/runtime.c", (10, 100), (0, 50)),
    _file("ske/abi/include/ske_abi.h", (5, 5), (0, 0)),
    _file("nodes/dds/agent.c", (3, 4), (1, 2)),
]}


def test_components_add_up_their_files():
    figures = code_coverage.components(SUMMARY)
    ske = figures["ske"]
    assert (ske["lines_covered"], ske["lines_total"]) == (105, 205)
    assert (ske["branches_covered"], ske["branches_total"]) == (40, 100)
    assert ske["line_percent"] == 51.2 and ske["branch_percent"] == 40.0
    assert figures["ske/src"]["line_percent"] == 90.0
    assert figures["ske/apex/src"]["branch_percent"] == 0.0
    assert figures["nodes"]["line_percent"] == figures["nodes/dds"]["line_percent"] == 75.0
    # Nothing measured: nothing missed.
    assert figures["health_monitor"]["line_percent"] == 100.0
    assert figures["health_monitor"]["lines_total"] == 0


def test_every_component_has_the_stable_fields():
    figures = code_coverage.components(SUMMARY)
    assert set(figures) == {*code_coverage.MEASURED, *code_coverage.PARTS}
    for f in figures.values():
        assert {"line_percent", "branch_percent"} <= set(f)


def test_report_and_table(tmp_path: Path):
    (tmp_path / code_coverage.FILES_REPORT).write_text(json.dumps(SUMMARY))
    path, figures = code_coverage.write_report(tmp_path)
    assert path == tmp_path / "coverage.json"
    assert json.loads(path.read_text()) == figures
    rows = code_coverage.table(figures).splitlines()
    assert rows[0].split()[:3] == ["component", "lines", "branches"]
    assert rows[1].split()[:3] == ["ske", "51.2%", "40.0%"]
    assert len(rows) == 1 + len(figures)


def test_gcovr_measures_the_product_not_its_tests():
    root, build = Path("/r"), Path("/r/build-coverage")
    cmd = code_coverage.gcovr_command("py", root, build)
    assert cmd[:3] == ["py", "-m", "gcovr"] and cmd[-1] == str(build)
    filters = [cmd[i + 1] for i, a in enumerate(cmd) if a == "--filter"]
    excludes = [cmd[i + 1] for i, a in enumerate(cmd) if a == "--exclude"]
    assert filters == ["/r/ske/", "/r/health_monitor/", "/r/nodes/"]
    assert "/r/(.+/)?tests?/" in excludes
    assert str(build / code_coverage.FILES_REPORT) in cmd


def test_the_instrumented_build_is_a_tree_of_its_own():
    configure, build = code_coverage.configure_commands(Path("/r"), Path("/r/build-coverage"))
    assert configure[configure.index("-B") + 1] == "/r/build-coverage"
    assert "-DIMA_COVERAGE=ON" in configure
    assert build == ["cmake", "--build", "/r/build-coverage"]


def test_reset_counters(tmp_path: Path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.c.gcda").write_bytes(b"")
    (tmp_path / "a" / "x.c.gcno").write_bytes(b"")
    assert code_coverage.reset_counters(tmp_path) == 1
    assert [p.name for p in (tmp_path / "a").iterdir()] == ["x.c.gcno"]
