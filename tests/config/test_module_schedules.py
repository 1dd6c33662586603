# SPDX-License-Identifier: Apache-2.0
"""Several module schedules (ARINC 653 Part 2) in a module: what the loader refuses, each with
one line naming the file, the line, the element and the rule."""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULE = ROOT / "tests" / "apex" / "schedule" / "test_set_module_schedule.xml"


def check(ske_binary, tmp_path, text: str):
    path = tmp_path / "module.xml"
    path.write_text(text)
    done = subprocess.run([str(ske_binary), "--check", str(path)], capture_output=True, text=True,
                          env={"IMA_PARTITION_PATH": str(ske_binary.parents[1] / "partitions")})
    return path, done


def line_of(text: str, needle: str) -> int:
    return text[: text.index(needle)].count("\n") + 1


def test_the_module_with_two_schedules_is_valid(ske_binary, tmp_path):
    _, done = check(ske_binary, tmp_path, MODULE.read_text())
    assert done.returncode == 0, done.stderr
    assert "valid module" in done.stdout


@pytest.mark.parametrize(
    ("old", "new", "at", "element", "rule"),
    [
        ('ScheduleName="DEGRADED" MajorFrameSeconds="0.04"',
         'ScheduleName="DEGRADED" InitialModuleSchedule="true" MajorFrameSeconds="0.04"',
         'ScheduleName="DEGRADED"', "Module_Schedule", "one initial module schedule"),
        ('ScheduleName="DEGRADED" MajorFrameSeconds="0.04"',
         'ScheduleName="DEGRADED" MajorFrameSeconds="0.08"',
         'ScheduleName="DEGRADED"', "Module_Schedule", "module schedules share the major frame"),
        ('ScheduleIdentifier="2"', 'ScheduleIdentifier="1"', 'ScheduleIdentifier="1" ScheduleName="DEGRADED"',
         "Module_Schedule", "module schedules have distinct identifiers and names"),
        ('ScheduleName="DEGRADED"', 'ScheduleName="NOMINAL"', 'ScheduleIdentifier="2"',
         "Module_Schedule", "module schedules have distinct identifiers and names"),
    ],
    ids=["two_initial", "different_major_frame", "same_identifier", "same_name"],
)
def test_schedule_rules(ske_binary, tmp_path, old, new, at, element, rule):
    text = MODULE.read_text()
    assert text.count(old) == 1
    bad = text.replace(old, new)
    path, done = check(ske_binary, tmp_path, bad)
    assert done.returncode == 2
    (line,) = done.stderr.splitlines()
    m = re.match(r"^(.*):(\d+): error: (\w+): (.*) \(rule: (.*)\)$", line)
    assert m, line
    assert (m[1], int(m[2]), m[3], m[5]) == (str(path), line_of(bad, at), element, rule)


def test_a_partition_keeps_its_period_in_every_schedule(ske_binary, tmp_path):
    text = MODULE.read_text()
    # In DEGRADED, the watcher's period halves (its window split in two to stay valid).
    degraded = text[text.index('ScheduleName="DEGRADED"'):]
    old_watcher = degraded[degraded.index('<Partition_Schedule PartitionIdentifier="3"'):]
    old_watcher = old_watcher[: old_watcher.index("</Partition_Schedule>") + len("</Partition_Schedule>")]
    new_watcher = (
        '<Partition_Schedule PartitionIdentifier="3" PartitionName="watcher" PeriodSeconds="0.02">\n'
        '      <Window_Schedule WindowIdentifier="2" WindowStartSeconds="0.01" WindowDurationSeconds="0.005"/>\n'
        '      <Window_Schedule WindowIdentifier="3" WindowStartSeconds="0.03" WindowDurationSeconds="0.005"/>\n'
        "    </Partition_Schedule>")
    bad = text.replace(old_watcher, new_watcher)
    path, done = check(ske_binary, tmp_path, bad)
    assert done.returncode == 2
    assert "(rule: a partition has the same period in every module schedule)" in done.stderr
    assert f"{path}:{line_of(bad, new_watcher)}: error: Partition_Schedule:" in done.stderr
