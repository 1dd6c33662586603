# SPDX-License-Identifier: Apache-2.0
"""ima-ske refuses invalid modules with one line naming file, line, element and rule.

Each case is the example module broken in one place by a text substitution; the expected line
is found in the edited text, so a case reads as a small diff of the example.
"""

from __future__ import annotations

import os
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "config" / "examples" / "three_partitions.xml"

EXIT_INVALID_MODULE = 2



@dataclass(frozen=True)
class Where:
    """The lines an element's start tag spans in a module (first == last for one line)."""

    first: int
    last: int


class Module:
    """A module's text, edited by exact substitutions, with the lines of what it contains."""

    def __init__(self, text: str) -> None:
        self.text = text

    def replace(self, old: str, new: str) -> Module:
        count = self.text.count(old)
        assert count == 1, f"{old!r} occurs {count} times in the module, expected once"
        return Module(self.text.replace(old, new))

    def without(self, first: str, last: str) -> Module:
        """Drops the lines from the one holding `first` to the next one holding `last`."""
        lines = self.text.splitlines(keepends=True)
        start = next(i for i, line in enumerate(lines) if first in line)
        end = next(i for i in range(start, len(lines)) if last in lines[i])
        return Module("".join(lines[:start] + lines[end + 1 :]))

    def _line_at(self, index: int) -> int:
        return self.text.count("\n", 0, index) + 1

    def _find(self, needle: str, after: str | None = None) -> int:
        start = self.text.index(after) if after is not None else 0
        return self.text.index(needle, start)

    def line_of(self, needle: str, after: str | None = None) -> int:
        """Line of the first `needle` (after the first `after`, if given)."""
        return self._line_at(self._find(needle, after))

    def tag(self, needle: str, after: str | None = None) -> Where:
        """Lines of the start tag that holds the first `needle`."""
        i = self._find(needle, after)
        return Where(
            self._line_at(self.text.rindex("<", 0, i + 1)), self._line_at(self.text.index(">", i))
        )

    def write(self, path: Path) -> Path:
        path.write_text(self.text, encoding="utf-8")
        return path


@dataclass
class Diagnostic:
    """One "FILE:LINE: error: [ELEMENT: ]message[ (rule: RULE)]" line."""

    file: str
    line: int
    rest: str  # "ELEMENT: message" or "message", without the rule
    rule: str | None

    @classmethod
    def parse(cls, text: str) -> Diagnostic:
        m = re.fullmatch(
            r"(?P<file>.+?):(?P<line>\d+): error: (?P<rest>.*?)"
            r"(?: \(rule: (?P<rule>[^()]*)\))?",
            text,
        )
        assert m, f"not a diagnostic line: {text!r}"
        return cls(m["file"], int(m["line"]), m["rest"], m["rule"])


def assert_refused(
    stderr: str,
    returncode: int,
    path: Path,
    *,
    at: Where,
    element: str,
    rule: str,
    says: tuple[str, ...] = (),
) -> None:
    """Exit status 2 and exactly one line on stderr, saying where and what.

    `element` "" means the line names no element (XML parse errors): `says` must then name it.
    """
    assert returncode == EXIT_INVALID_MODULE, f"exit status {returncode}, stderr:\n{stderr}"
    lines = stderr.splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}:\n{stderr}"
    d = Diagnostic.parse(lines[0])
    assert d.file == str(path), lines[0]
    if element:
        assert d.rest.startswith(f"{element}: "), f"element {element!r} not named: {lines[0]}"
    for fragment in says:
        assert fragment in d.rest, f"{fragment!r} not said: {lines[0]}"

    assert d.line == at.first, f"line {d.line}, expected {at.first}: {lines[0]}"
    assert d.rule == rule, f"rule {d.rule!r}, expected {rule!r}: {lines[0]}"


@pytest.fixture
def example() -> Module:
    return Module(EXAMPLE.read_text(encoding="utf-8"))


@pytest.fixture
def check(run_ske, tmp_path):
    """check(module) -> (path it was written to, ima-ske --check result)."""

    def run(module: Module):
        path = module.write(tmp_path / "module.xml")
        return path, run_ske(path, frames=None, trace=False, args=["--check"])

    return run


def refused(
    check, module: Module, *, at: Where, element: str, rule: str, says: tuple[str, ...] = ()
) -> None:
    path, r = check(module)
    assert r.stdout == ""
    assert_refused(r.stderr, r.returncode, path, at=at, element=element, rule=rule, says=says)


# ---- the example itself --------------------------------------------------------------------


def test_example_passes_check(run_ske, check, example):
    r = run_ske(EXAMPLE, frames=None, trace=False, args=["--check"])
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout == (
        f"{EXAMPLE}: valid module 'three_partitions': 3 partitions, 4 windows, "
        f"2 channels, major frame 0.050000 s\n"
    )
    # The copy every case starts from is valid too: nothing depends on where it is written.
    path, r = check(example)
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout.startswith(f"{path}: valid module 'three_partitions': 3 partitions")


# ---- schedule --------------------------------------------------------------------------------


def overlapping(example: Module) -> Module:
    # The consumer's window now starts 5 ms into the producer's [0, 10 ms) window.
    return example.replace(
        'WindowStartSeconds="0.01" WindowDurationSeconds="0.012"',
        'WindowStartSeconds="0.005" WindowDurationSeconds="0.012"',
    )


def test_overlapping_windows(check, example):
    bad = overlapping(example)
    refused(
        check,
        bad,
        at=bad.tag('<Window_Schedule WindowIdentifier="2"'),
        element="Window_Schedule",
        rule="windows of a module schedule do not overlap",
        says=("window 2 of partition 'consumer'", "overlaps window 1 of partition 'producer'"),
    )


def test_window_past_major_frame(check, example):
    # 38 ms + 13 ms ends 1 ms after the 50 ms major frame.
    bad = example.replace(
        'WindowStartSeconds="0.038" WindowDurationSeconds="0.008"',
        'WindowStartSeconds="0.038" WindowDurationSeconds="0.013"',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Window_Schedule WindowIdentifier="5"'),
        element="Window_Schedule",
        rule="windows end within the major frame",
        says=("window 5 of partition 'monitor'", "past the major frame"),
    )


def test_window_far_past_major_frame(check, example):
    bad = example.replace(
        'WindowStartSeconds="0.038" WindowDurationSeconds="0.008"',
        'WindowStartSeconds="9000000000" WindowDurationSeconds="9000000000"',
    ).replace('PeriodDurationSeconds="0.008"', 'PeriodDurationSeconds="9000000000"')
    refused(
        check,
        bad,
        at=bad.tag('<Window_Schedule WindowIdentifier="5"'),
        element="Window_Schedule",
        rule="windows end within the major frame",
        says=("window 5 of partition 'monitor'", "past the major frame"),
    )


def test_schedule_names_unknown_partition_id(check, example):
    bad = example.replace(
        '<Partition_Schedule PartitionIdentifier="2" PartitionName="consumer"',
        '<Partition_Schedule PartitionIdentifier="7" PartitionName="consumer"',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Partition_Schedule PartitionIdentifier="7"'),
        element="Partition_Schedule",
        rule="references name a declared Partition",
        says=("unknown partition", "PartitionIdentifier=7"),
    )


def test_schedule_id_and_name_disagree(check, example):
    bad = example.replace(
        '<Partition_Schedule PartitionIdentifier="2" PartitionName="consumer"',
        '<Partition_Schedule PartitionIdentifier="2" PartitionName="monitor"',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Partition_Schedule PartitionIdentifier="2"'),
        element="Partition_Schedule",
        rule="PartitionIdentifier and PartitionName name the same partition",
        says=("PartitionIdentifier=2 is partition 'consumer', not 'monitor'",),
    )


def test_partition_without_window(check, example):
    bad = example.without('<Partition_Schedule PartitionIdentifier="3"', "</Partition_Schedule>")
    refused(
        check,
        bad,
        at=bad.tag('<Partition PartitionIdentifier="3"'),
        element="Partition",
        rule="every partition has at least one window",
        says=("'monitor' has no window",),
    )


def test_period_does_not_divide_major_frame(check, example):
    bad = example.replace(
        'PartitionName="monitor" PeriodSeconds="0.05"',
        'PartitionName="monitor" PeriodSeconds="0.03"',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Partition_Schedule PartitionIdentifier="3"'),
        element="Partition_Schedule",
        rule="the partition period divides the major frame",
        says=(
            "PeriodSeconds of partition 'monitor' (30000000 ns) does not divide the major "
            "frame (50000000 ns)",
        ),
    )


def test_period_duration_disagrees_with_windows(check, example):
    # The producer's two windows give 10 + 5 ms per period; 10 ms forgets the second one.
    bad = example.replace('PeriodDurationSeconds="0.015"', 'PeriodDurationSeconds="0.01"')
    refused(
        check,
        bad,
        at=bad.tag('<Partition_Schedule PartitionIdentifier="1"'),
        element="Partition_Schedule",
        rule="PeriodDurationSeconds is the window time per period",
        says=("'producer' declares 10000000 ns per period but its windows give 15000000 ns",),
    )


# ---- partitions and ports ---------------------------------------------------------------------


def test_duplicate_partition_id(check, example):
    bad = example.replace(
        '<Partition PartitionIdentifier="3" PartitionName="monitor"',
        '<Partition PartitionIdentifier="2" PartitionName="monitor"',
    )
    refused(
        check,
        bad,
        at=bad.tag('PartitionName="monitor" Criticality'),
        element="Partition",
        rule="partition identifiers are unique",
        says=("PartitionIdentifier=2 is already used by partition 'consumer'",),
    )


@pytest.mark.parametrize(
    "executable, says",
    [
        ("ex_monitr", "'ex_monitr' not found in the partition path"),
        ("bin/ex_monitor", "'bin/ex_monitor' not found"),  # relative to the module's folder
    ],
    ids=["bare-name", "relative-path"],
)
def test_missing_executable(check, example, executable, says):
    # --check resolves executables as a run does.
    bad = example.replace(
        '<ima:Linux Executable="ex_monitor"/>', f'<ima:Linux Executable="{executable}"/>'
    )
    refused(
        check,
        bad,
        at=bad.tag('<Partition PartitionIdentifier="3"'),
        element="Partition",
        rule="the partition's program exists",
        says=("partition 'monitor'", says),
    )


def test_malformed_number(check, example):
    bad = example.replace('Name="QP_CMD" MaxMessageSize="32"', 'Name="QP_CMD" MaxMessageSize="12x"')
    refused(
        check,
        bad,
        at=bad.tag('MaxMessageSize="12x"'),
        element="Queuing_Port",
        rule="numbers are positive integers",
        says=("MaxMessageSize", "'12x'"),
    )


@pytest.mark.parametrize("value", ["abc", "1e-3", "-0.01", "0.0000000001"])
def test_malformed_duration(check, example, value):
    bad = example.replace('WindowDurationSeconds="0.012"', f'WindowDurationSeconds="{value}"')
    refused(
        check,
        bad,
        at=bad.tag('<Window_Schedule WindowIdentifier="2"'),
        element="Window_Schedule",
        rule="durations are decimal seconds",
        says=("WindowDurationSeconds", f"'{value}'"),
    )


# ---- channels ----------------------------------------------------------------------------------


def test_channel_ports_differ_in_size(check, example):
    bad = example.replace(
        'Name="SP_STATE_MON" MaxMessageSize="64"', 'Name="SP_STATE_MON" MaxMessageSize="48"'
    )
    refused(
        check,
        bad,
        at=bad.tag('<Destination><Standard_Partition PartitionIdentifier="3"'),
        element="Destination",
        rule="the ports of a channel have the same MaxMessageSize",
        says=("channel 'state'", "MaxMessageSize=64", "'SP_STATE_MON'", "has 48"),
    )


def test_channel_source_is_destination_port(check, example):
    # Source and destination of the command channel swapped.
    producer = 'PartitionIdentifier="1" PartitionName="producer" PortName="QP_CMD"'
    consumer = 'PartitionIdentifier="2" PartitionName="consumer" PortName="QP_CMD_IN"'
    bad = example.replace(
        f"<Source><Standard_Partition {producer}/>", f"<Source><Standard_Partition {consumer}/>"
    ).replace(
        f"<Destination><Standard_Partition {consumer}/>",
        f"<Destination><Standard_Partition {producer}/>",
    )
    refused(
        check,
        bad,
        at=bad.tag(f"<Source><Standard_Partition {consumer}"),
        element="Source",
        rule="a channel's Source is a SOURCE port",
        says=(
            "port 'QP_CMD_IN' of partition 'consumer' is a DESTINATION port",
            "channel 'commands'",
        ),
    )


def test_channel_destination_is_source_port(check, example):
    # The monitor declares its input as an output.
    bad = example.replace(
        'Name="SP_STATE_MON" MaxMessageSize="64" Direction="DESTINATION"',
        'Name="SP_STATE_MON" MaxMessageSize="64" Direction="SOURCE"',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Destination><Standard_Partition PartitionIdentifier="3"'),
        element="Destination",
        rule="a channel's Destination is a DESTINATION port",
        says=("port 'SP_STATE_MON' of partition 'monitor' is a SOURCE port", "channel 'state'"),
    )


def test_channel_names_undeclared_port(check, example):
    bad = example.replace('PortName="QP_CMD_IN"', 'PortName="QP_CMDS_IN"')
    refused(
        check,
        bad,
        at=bad.tag('PortName="QP_CMDS_IN"'),
        element="Standard_Partition",
        rule="a channel connects ports that partitions declare",
        says=("partition 'consumer' declares no port named 'QP_CMDS_IN'",),
    )


def test_queuing_channel_with_two_destinations(check, example):
    monitor_port = '<Sampling_Port Name="SP_STATE_MON"'
    destination = (
        '<Destination><Standard_Partition PartitionIdentifier="2" '
        'PartitionName="consumer" PortName="QP_CMD_IN"/></Destination>'
    )
    bad = example.replace(
        monitor_port,
        '<Queuing_Port Name="QP_CMD_MON" MaxMessageSize="32" Direction="DESTINATION" '
        f'MaxNbMessages="8"/>\n    {monitor_port}',
    ).replace(
        destination,
        f"{destination}\n      <Destination><Standard_Partition "
        'PartitionIdentifier="3" PartitionName="monitor" PortName="QP_CMD_MON"/>'
        "</Destination>",
    )
    refused(
        check,
        bad,
        at=bad.tag('<Channel ChannelIdentifier="2"'),
        element="Channel",
        rule="a queuing channel has exactly one destination",
        says=("queuing channel 'commands' has 2 destinations",),
    )


def test_sampling_channel_to_queuing_port(check, example):
    # The monitor declares its state input as a queuing port.
    bad = example.replace(
        '<Sampling_Port Name="SP_STATE_MON" MaxMessageSize="64" Direction="DESTINATION" '
        'RefreshRateSeconds="0.1"/>',
        '<Queuing_Port Name="SP_STATE_MON" MaxMessageSize="64" Direction="DESTINATION" '
        'MaxNbMessages="4"/>',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Destination><Standard_Partition PartitionIdentifier="3"'),
        element="Destination",
        rule="a channel connects ports of one kind",
        says=("sampling port 'SP_STATE'", "queuing port 'SP_STATE_MON' of partition 'monitor'"),
    )


# ---- XML -----------------------------------------------------------------------------------------


def test_not_well_formed(check, example):
    # A Process element left open: the parser finds out at the partition's end tag.
    bad = example.replace(
        '<Process Name="watch" StackSize="65536"/>', '<Process Name="watch" StackSize="65536">'
    )
    line = bad.line_of("</Partition>", after='<Process Name="watch"')
    refused(
        check,
        bad,
        at=Where(line, line),
        element="",
        rule="well-formed XML",
        says=("Process", "Partition"),
    )


def test_unknown_element(check, example):
    bad = example.replace(
        '<ima:Linux Executable="ex_monitor"/>',
        '<Watchdog TimeoutSeconds="0.1"/>\n    <ima:Linux Executable="ex_monitor"/>',
    )
    refused(
        check,
        bad,
        at=bad.tag("<Watchdog"),
        element="Watchdog",
        rule="schema ima653_module.xsd",
        says=("Watchdog", "not expected"),
    )


# ---- through the ima command, as a user runs it --------------------------------------------------


def test_ima_run_refuses_overlapping_windows(example, tmp_path):
    bad = overlapping(example)
    path = bad.write(tmp_path / "overlapping.xml")
    env = dict(os.environ, IMA_SKIP_BUILD="1")
    r = subprocess.run(
        [str(ROOT / "ima"), "run", str(path)], capture_output=True, text=True, timeout=300, env=env
    )
    assert r.stdout == ""
    assert_refused(
        r.stderr,
        r.returncode,
        path,
        at=bad.tag('<Window_Schedule WindowIdentifier="2"'),
        element="Window_Schedule",
        rule="windows of a module schedule do not overlap",
        says=("window 2 of partition 'consumer'", "overlaps window 1"),
    )


# ---- partition periods within a longer major frame -----------------------------------------------


def two_periods_per_frame(example: Module) -> Module:
    """The example with a 100 ms major frame: the producer and the consumer keep one period
    per frame (100 ms), the monitor keeps its 50 ms period, so it has two per frame."""
    return (
        example.replace('MajorFrameSeconds="0.05"', 'MajorFrameSeconds="0.1"')
        .replace(
            'PartitionName="producer" PeriodSeconds="0.05"',
            'PartitionName="producer" PeriodSeconds="0.1"',
        )
        .replace(
            'PartitionName="consumer" PeriodSeconds="0.05"',
            'PartitionName="consumer" PeriodSeconds="0.1"',
        )
    )


def test_partition_period_without_window_time(check, example):
    # The monitor's one 8 ms window lies in the first of its two periods: 4 ms per period on
    # average, but 8 ms in one and none in the other (ARINC 653 Part 1, 2.3.1.3).
    bad = two_periods_per_frame(example).replace(
        'PeriodDurationSeconds="0.008"', 'PeriodDurationSeconds="0.004"'
    )
    refused(
        check,
        bad,
        at=bad.tag('<Partition_Schedule PartitionIdentifier="3"'),
        element="Partition_Schedule",
        rule="every partition period gets the same window time",
        says=(
            "partition 'monitor' gets",
            "4000000 ns per period on average",
            "(period 50000000 ns)",
        ),
    )


def test_window_crossing_its_partition_period(check, example):
    # The monitor's periods start at 38 ms (its PartitionPeriodStart window) and 88 ms; a
    # second 10 ms window at 80 ms gives each period 9 ms on average but runs into the second.
    monitor_window = (
        '<Window_Schedule WindowIdentifier="5" WindowStartSeconds="0.038" '
        'WindowDurationSeconds="0.008"\n                       PartitionPeriodStart="true"/>'
    )
    bad = (
        two_periods_per_frame(example)
        .replace('PeriodDurationSeconds="0.008"', 'PeriodDurationSeconds="0.009"')
        .replace(
            monitor_window,
            f'{monitor_window}\n      <Window_Schedule WindowIdentifier="6" '
            'WindowStartSeconds="0.08" WindowDurationSeconds="0.01"/>',
        )
    )
    refused(
        check,
        bad,
        at=bad.tag('<Window_Schedule WindowIdentifier="6"'),
        element="Window_Schedule",
        rule="a window stays within its partition period",
        says=(
            "window 6 of partition 'monitor' starts at 80000000 ns",
            "past the end of its partition period at 88000000 ns",
        ),
    )


# ---- what a schema error says ------------------------------------------------------------------


def test_missing_required_number_says_it_is_missing(check, example):
    # Not "MaxNbMessages='' is not a valid number": the attribute is not there at all.
    bad = example.replace(
        '<Queuing_Port Name="QP_CMD" MaxMessageSize="32" Direction="SOURCE" MaxNbMessages="8"/>',
        '<Queuing_Port Name="QP_CMD" MaxMessageSize="32" Direction="SOURCE"/>',
    )
    refused(
        check,
        bad,
        at=bad.tag('<Queuing_Port Name="QP_CMD"'),
        element="Queuing_Port",
        rule="schema ima653_module.xsd",
        says=("The attribute 'MaxNbMessages' is required but missing",),
    )


def test_number_above_its_maximum_says_the_maximum(check, example):
    bad = example.replace(
        'Name="QP_CMD" MaxMessageSize="32" Direction="SOURCE" MaxNbMessages="8"',
        'Name="QP_CMD" MaxMessageSize="32" Direction="SOURCE" MaxNbMessages="2000000"',
    )
    refused(
        check,
        bad,
        at=bad.tag('MaxNbMessages="2000000"'),
        element="Queuing_Port",
        rule="numbers are within their range",
        says=("MaxNbMessages='2000000' is too large: at most 1048576",),
    )


# ---- hostile module files --------------------------------------------------------------------


def test_a_document_type_declaration_is_refused_before_parsing(check, example):
    """Module files need no DTD; one could define entities that expand beyond any bound (a
    file of a few kilobytes became hundreds of megabytes), so none is processed."""
    entities = "".join(f'<!ENTITY e{k} "{f"&e{k - 1};" * 16 if k else "x" * 64}">'
                       for k in range(12))
    bad = Module(example.text.replace("<ARINC_653_Module",
                                      f"<!DOCTYPE ARINC_653_Module [{entities}]>\n"
                                      "<ARINC_653_Module", 1))
    refused(check, bad, at=Where(bad.line_of("<!DOCTYPE"), bad.line_of("<!DOCTYPE")),
            element="", rule="no document type declaration", says=("DOCTYPE",))


def test_a_module_file_beyond_8_mib_is_refused(check, example):
    big = Module(example.text + "<!--" + "x" * (8 << 20) + "-->\n")
    path, r = check(big)
    assert r.returncode == EXIT_INVALID_MODULE and "larger than 8 MiB" in r.stderr, r.stderr


def test_a_memory_requirement_of_no_bytes_is_refused(check, example):
    first = example.text.index("SizeBytes=")
    value = example.text[first:example.text.index(" ", first)]
    bad = Module(example.text.replace(value, 'SizeBytes="0"', 1))
    refused(check, bad, at=bad.tag('SizeBytes="0"'), element="Memory_Requirements",
            rule="a memory requirement is at least one byte", says=("SizeBytes",))


@pytest.mark.parametrize("name, says", [("", "empty"), ("m" * 5000, "longer than 63")])
def test_a_module_name_is_1_to_63_characters(check, example, name, says):
    bad = example.replace('ModuleName="three_partitions"', f'ModuleName="{name}"')
    refused(check, bad, at=bad.tag("<ARINC_653_Module"), element="ARINC_653_Module",
            rule="a module name of 1 to 63 characters", says=(says,))


def test_a_parse_error_that_quotes_the_file_is_still_one_line(check, example):
    """libxml2 quotes the input around some errors, newlines and all (found by tests/fuzz)."""
    text = example.text
    cut = text.index("<Module_Schedule")
    bad = Module(text[:cut] + "<![CDATA[\n" + text[cut:])
    path, r = check(bad)
    assert r.returncode == EXIT_INVALID_MODULE and len(r.stderr.splitlines()) == 1, r.stderr
    assert "CData section not finished" in r.stderr and "(rule: well-formed XML)" in r.stderr
