# SPDX-License-Identifier: Apache-2.0
"""docs/apex-coverage.md stays true: it lists every service the APEX headers declare, each
with the conformance test that exists for it, and docs/writing-a-partition.md documents each
one's return codes."""

from pathlib import Path

from ima import apex_coverage

ROOT = Path(__file__).resolve().parents[2]


def test_every_declared_service_has_a_conformance_test():
    services = apex_coverage.services(ROOT)
    assert len(services) >= 59
    missing = [s for s, _ in services if apex_coverage.test_file(s, ROOT) is None]
    assert missing == []


def test_the_coverage_page_holds_the_derived_table():
    page = (ROOT / "docs" / "apex-coverage.md").read_text()
    assert apex_coverage.table(ROOT) in page, "regenerate it: python -m ima.apex_coverage"


def test_every_service_has_its_return_codes_documented():
    guide = (ROOT / "docs" / "writing-a-partition.md").read_text()
    undocumented = [s for s, _ in apex_coverage.services(ROOT) if f"| `{s}` |" not in guide]
    assert undocumented == []
