# SPDX-License-Identifier: Apache-2.0
"""A partition's standard output is line-buffered by the APEX library before main().

Three partitions print lines of about 130 bytes, 24 per window, in turns; in its third window
"killed" kills itself (SIGKILL, as a process ended by the health monitor or a restart) and
"idled" goes IDLE (ima-ske ends its process); "steady" goes on. Every complete line each of
them printed is in ima-ske's standard output, whole, and nothing else is: no line cut in two
or run into another partition's.
"""

import re
from pathlib import Path

import pytest

MODULE = Path(__file__).with_suffix(".xml")
FRAMES = 5
LINES_PER_WINDOW = 24
LINE = re.compile(r"^(killed|idled|steady) line (\d{3}) \.{114}$")


@pytest.fixture
def run_once(run_ske):
    return run_ske(MODULE, frames=FRAMES, timeout=30.0)


def test_every_complete_line_is_in_the_output_whole(run_once):
    r = run_once
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    malformed = [line for line in lines if not LINE.match(line)]
    assert malformed == [], f"lines cut or mixed: {malformed[:3]}"
    printed = {}
    for line in lines:
        m = LINE.match(line)
        printed.setdefault(m[1], []).append(int(m[2]))
    # killed and idled printed in three windows before their end, steady in every frame.
    assert printed == {
        "killed": list(range(3 * LINES_PER_WINDOW)),
        "idled": list(range(3 * LINES_PER_WINDOW)),
        "steady": list(range(FRAMES * LINES_PER_WINDOW)),
    }


def test_the_partitions_really_ended(run_once):
    r = run_once
    exits = r.of_kind("partition_exit", partition="killed")
    assert len(exits) == 1 and exits[0]["status"] == "crashed" and exits[0]["signal"] == "KILL"
    assert r.of_kind("mode", partition="idled", mode="IDLE")
    assert r.app_messages("killed") == [f"killing itself after {3 * LINES_PER_WINDOW} lines"]
    assert r.app_messages("idled") == [f"going idle after {3 * LINES_PER_WINDOW} lines"]
