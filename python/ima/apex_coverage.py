# SPDX-License-Identifier: Apache-2.0
"""The APEX coverage table of docs/apex-coverage.md, derived from the headers and the tests.

Every service the APEX headers declare, the header (service group) declaring it, and the
conformance test that runs it under the real SKE. `python -m ima.apex_coverage` prints the
table; a test checks that the page holds exactly this table.
"""

from __future__ import annotations

import re
from pathlib import Path

from ima import paths

# Services tested together with another, in the file named here.
SHARED_TESTS = {
    "CREATE_ERROR_HANDLER": "health/test_error_handler",
    "GET_ERROR_STATUS": "health/test_error_handler",
    "RAISE_APPLICATION_ERROR": "health/test_error_handler",
    "REPORT_APPLICATION_MESSAGE": "health/test_error_handler",
    "GET_MODULE_SCHEDULE_STATUS": "schedule/test_set_module_schedule",
    "GET_MODULE_SCHEDULE_ID": "schedule/test_set_module_schedule",
}

GROUPS = {
    "apex_partition.h": "Partition management (Part 1, 3.2)",
    "apex_process.h": "Process management (Part 1, 3.3)",
    "apex_time.h": "Time management (Part 1, 3.4)",
    "apex_sampling.h": "Sampling ports (Part 1, 3.6.2.1)",
    "apex_sampling_ext.h": "Sampling port extensions (Part 2)",
    "apex_queuing.h": "Queuing ports (Part 1, 3.6.2.2)",
    "apex_buffer.h": "Buffers (Part 1, 3.7.2.1)",
    "apex_blackboard.h": "Blackboards (Part 1, 3.7.2.2)",
    "apex_semaphore.h": "Semaphores (Part 1, 3.7.2.3)",
    "apex_event.h": "Events (Part 1, 3.7.2.4)",
    "apex_error.h": "Health monitoring (Part 1, 3.10)",
    "apex_schedule.h": "Multiple module schedules (Part 2, 3.2)",
}

_DECL = re.compile(r"^extern void ([A-Z_]+)\s*\(", re.M)


def services(root: Path | None = None) -> list[tuple[str, str]]:
    """(service, header) for every service the APEX headers declare, in header order."""
    include = (root or paths.repo_root()) / "ske" / "apex" / "include"
    found = []
    for header in sorted(include.glob("apex_*.h")):
        for name in _DECL.findall(header.read_text()):
            found.append((name, header.name))
    return found


def test_file(service: str, root: Path | None = None) -> str | None:
    """The conformance test (tests/apex/<folder>/test_<call>) that covers a service, if any."""
    apex = (root or paths.repo_root()) / "tests" / "apex"
    name = SHARED_TESTS.get(service)
    if name is None:
        hits = sorted(apex.glob(f"*/test_{service.lower()}.py"))
        if not hits:
            return None
        name = f"{hits[0].parent.name}/{hits[0].stem}"
    return name if (apex / f"{name}.py").is_file() else None


def table(root: Path | None = None) -> str:
    lines = []
    for header, group in GROUPS.items():
        rows = [s for s, h in services(root) if h == header]
        if not rows:
            continue
        lines += [f"### {group}", "", "| Service | Status | Conformance test |", "|---|---|---|"]
        for service in rows:
            test = test_file(service, root)
            where = f"`tests/apex/{test}.py`" if test else "none"
            lines.append(f"| `{service}` | implemented | {where} |")
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table())
