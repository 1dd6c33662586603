# SPDX-License-Identifier: Apache-2.0
"""A bad system model is refused with one line naming the file, the line and the path of the
bad value. Each case is the triplex model changed in one place."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml

from ima.deploy import load_system
from ima.errors import ImaError

ROOT = Path(__file__).resolve().parents[2]
TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"


@pytest.fixture(scope="module")
def good() -> dict:
    """The triplex model in one file: the system file with the application it includes."""
    doc = yaml.safe_load(TRIPLEX.read_text())
    included = TRIPLEX.parent / doc.pop("include")
    doc.update(yaml.safe_load(included.read_text()))
    # The copies live in a temporary folder: point them at the repository's bus files.
    doc["channels"]["can"]["dbc"] = str(ROOT / "config" / "can" / "rpas.dbc")
    doc["channels"]["dds"]["config"] = str(ROOT / "config" / "dds" / "cyclonedds-loopback.xml")
    return doc


def refuse(tmp_path: Path, good: dict, edit: Callable[[dict], object]) -> tuple[str, list[str]]:
    """Writes the good model changed by `edit`, loads it; returns (error message, file lines)."""
    doc = copy.deepcopy(good)
    edit(doc)
    path = tmp_path / "system.yaml"
    text = yaml.safe_dump(doc, sort_keys=False, default_flow_style=False)
    path.write_text(text)
    with pytest.raises(ImaError) as err:
        load_system(path)
    assert err.value.exit_code == 2
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}:"), msg
    return msg, text.splitlines()


def line_of(msg: str) -> int:
    """The LINE of a `FILE:LINE: ...` message."""
    return int(msg.split(":", 2)[1])


def test_the_models_load() -> None:
    triplex = load_system(TRIPLEX)
    simplex = load_system(ROOT / "config" / "systems" / "rpas_simplex.yaml")
    # one partition set, included by both
    assert triplex.included == simplex.included == [ROOT / "config" / "applications" / "rpas.yaml"]
    assert triplex.partitions == simplex.partitions


# --- the schema ------------------------------------------------------------------------------

def set_in(doc: dict, path: tuple, value) -> None:
    for p in path[:-1]:
        doc = doc[p]
    doc[path[-1]] = value


SCHEMA_CASES = [
    (("nodes", 1, "index"), 7, "nodes[1].index: 7 is greater than the maximum of 3", "index: 7"),
    (("nodes", 0, "index"), 0, "nodes[0].index: 0 is less than the minimum of 1", "index: 0"),
    (("partitions", 0, "criticality"), "LEVEL_F",
     "partitions[0].criticality: 'LEVEL_F' is not one of ['LEVEL_A', ", "LEVEL_F"),
    (("partitions", 1, "ports", 2, "size"), "40",
     "partitions[1].ports[2].size: '40' is not of type 'integer'", "size: '40'"),
    (("partitions", 1, "personality"), "posix",
     "partitions[1].personality: 'posix' is not one of ['apex-c']", "posix"),
    (("partitions", 0, "processes", 1, "priority"), 400,
     "partitions[0].processes[1].priority: 400 is greater than the maximum of 239", "400"),
    (("partitions", 0, "health_monitoring", "PROCESS", "NUMERIC_ERROR"), "REBOOT",
     "partitions[0].health_monitoring.PROCESS.NUMERIC_ERROR: 'REBOOT' is not one of ", "REBOOT"),
    (("schedule", "windows", 1, "duration_s"), 0,
     "schedule.windows[1].duration_s: 0 is less than or equal to the minimum of 0",
     "duration_s: 0"),
    (("channels", "intra_node", 0, "from"), "GPS_OUT",
     "channels.intra_node[0].from: 'GPS_OUT' does not match ", "from: GPS_OUT"),
    (("channels", "can", "bitrate"), "1M",
     "channels.can.bitrate: '1M' is not of type 'integer'", "bitrate: 1M"),
    (("voting", "persist"), 0, "voting.persist: 0 is less than the minimum of 1", "persist: 0"),
    (("membership", "missed_frames"), 1.5,
     "membership.missed_frames: 1.5 is not of type 'integer'", "missed_frames: 1.5"),
    (("nodes", 2, "name"), "node 3", "nodes[2].name: 'node 3' does not match ", "node 3"),
]


@pytest.mark.parametrize(("path", "value", "expected", "on_line"), SCHEMA_CASES,
                         ids=[c[2].split(":")[0] for c in SCHEMA_CASES])
def test_schema_errors_name_the_path_and_line(tmp_path, good, path, value, expected,
                                              on_line) -> None:
    msg, lines = refuse(tmp_path, good, lambda d: set_in(d, path, value))
    assert f": {expected}" in msg, msg
    assert on_line in lines[line_of(msg) - 1], (msg, lines[line_of(msg) - 1])


def test_a_missing_property(tmp_path, good) -> None:
    msg, _ = refuse(tmp_path, good, lambda d: d["voting"]["thresholds"].pop("thr"))
    assert msg.endswith(": voting.thresholds: 'thr' is a required property"), msg


def test_an_unknown_property(tmp_path, good) -> None:
    msg, lines = refuse(tmp_path, good, lambda d: d["nodes"][0].update(channel="A"))
    assert msg.endswith(": nodes[0]: Additional properties are not allowed ('channel' was "
                        "unexpected)"), msg
    assert "name: node1" in lines[line_of(msg) - 1]


def test_a_misspelt_top_level_key(tmp_path, good) -> None:
    msg, _ = refuse(tmp_path, good, lambda d: d.update(replicated_partitions=d.pop("replicated")))
    assert ": (top level): 'replicated' is a required property" in msg
    assert "('replicated_partitions' was unexpected)" in msg


def test_a_sampling_port_needs_a_refresh_period(tmp_path, good) -> None:
    msg, _ = refuse(tmp_path, good, lambda d: d["partitions"][0]["ports"][3].pop("refresh_s"))
    assert msg.endswith(": partitions[0].ports[3]: 'refresh_s' is a required property"), msg


def test_a_queuing_port_needs_a_capacity(tmp_path, good) -> None:
    msg, _ = refuse(tmp_path, good,
                    lambda d: d["partitions"][0]["ports"].append(
                        {"name": "Q", "direction": "source", "kind": "queuing", "size": 8}))
    assert msg.endswith(": partitions[0].ports[13]: 'max_messages' is a required property"), msg


def test_several_errors_are_listed_with_their_lines(tmp_path, good) -> None:
    def edit(d):
        d["nodes"][1]["index"] = 7
        d["voting"]["persist"] = 0

    msg, _ = refuse(tmp_path, good, edit)
    assert f"nodes[1].index: 7 is greater than the maximum of 3; {tmp_path / 'system.yaml'}:" in msg
    assert ": voting.persist: 0 is less than the minimum of 1" in msg


def test_a_whole_number_version_is_a_version(tmp_path, good) -> None:
    doc = copy.deepcopy(good)
    doc["version"] = 2
    path = tmp_path / "system.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    assert load_system(path).version == "2"


APPLICATION = ROOT / "config" / "applications" / "rpas.yaml"


def _included(tmp_path: Path, app_text: str, system_text: str | None = None) -> Path:
    """A copy of the triplex (system file and application) in tmp_path, the application's
    text given; returns the system file."""
    (tmp_path / "applications").mkdir()
    (tmp_path / "applications" / "rpas.yaml").write_text(
        app_text.replace("../can/", f"{ROOT}/config/can/").replace("../dds/", f"{ROOT}/config/dds/"))
    (tmp_path / "systems").mkdir()
    path = tmp_path / "systems" / "rpas_triplex.yaml"
    path.write_text(system_text if system_text is not None else TRIPLEX.read_text())
    return path


def test_a_key_given_twice(tmp_path) -> None:
    path = _included(tmp_path, APPLICATION.read_text().replace("  persist: 3\n",
                                                               "  persist: 3\n  persist: 4\n"))
    app = tmp_path / "applications" / "rpas.yaml"
    line = app.read_text().splitlines().index("  persist: 4") + 1
    with pytest.raises(ImaError, match=rf"^{app}:{line}: voting: key 'persist' appears twice$"):
        load_system(path)


def test_an_error_in_the_included_file_names_that_file(tmp_path) -> None:
    text = APPLICATION.read_text().replace("  persist: 3\n", "  persist: 0\n")
    path = _included(tmp_path, text)
    app = tmp_path / "applications" / "rpas.yaml"
    line = text.splitlines().index("  persist: 0") + 1
    with pytest.raises(ImaError, match=rf"^{app}:{line}: voting.persist: 0 is less than the "
                                       "minimum of 1$"):
        load_system(path)


def test_a_key_in_both_files(tmp_path) -> None:
    system = TRIPLEX.read_text() + "voting: {thresholds: {elev: 1}, persist: 1, offset_s: 0}\n"
    path = _included(tmp_path, APPLICATION.read_text(), system)
    app = tmp_path / "applications" / "rpas.yaml"
    app_line = app.read_text().splitlines().index("voting:") + 1
    line = system.splitlines().index("voting: {thresholds: {elev: 1}, persist: 1, offset_s: 0}") + 1
    with pytest.raises(ImaError, match=rf"^{path}:{line}: voting: also written in "
                                       rf"{app}:{app_line}: a key is written in one file only$"):
        load_system(path)


def test_an_included_file_includes_nothing(tmp_path) -> None:
    path = _included(tmp_path, "include: other.yaml\n" + APPLICATION.read_text())
    with pytest.raises(ImaError, match=r"rpas.yaml:1: include: an included file includes "
                                       "nothing further$"):
        load_system(path)


def test_an_include_that_is_not_there(tmp_path) -> None:
    path = tmp_path / "system.yaml"
    path.write_text("include: nope.yaml\nsystem: s\n")
    with pytest.raises(ImaError, match=rf"^{path}:1: include: no such file: {tmp_path}/nope.yaml$"):
        load_system(path)
    path.write_text("include: [a.yaml]\nsystem: s\n")
    with pytest.raises(ImaError, match=rf"^{path}:1: include: expected the path of a YAML file"):
        load_system(path)


def test_not_yaml(tmp_path) -> None:
    path = tmp_path / "system.yaml"
    path.write_text("system: x\nnodes: [\n  {name: a\n")
    with pytest.raises(ImaError, match=rf"^{path}:\d+: not valid YAML: "):
        load_system(path)


def test_a_missing_file(tmp_path) -> None:
    with pytest.raises(ImaError, match=rf"^{tmp_path / 'nope.yaml'}: no such system file$"):
        load_system(tmp_path / "nope.yaml")


# --- the rules a schema cannot express ---------------------------------------------------------

def window(d: dict, i: int) -> dict:
    return d["schedule"]["windows"][i]


SEMANTIC_CASES = [
    ("duplicate node name", lambda d: d["nodes"][1].update(name="node1"),
     "nodes[1].name: 'node1' is already the name of nodes[0]", "name: node1"),
    ("duplicate node index", lambda d: d["nodes"][2].update(index=1),
     "nodes[2].index: 1 is already the index (redundancy channel) of nodes[0] (node1)",
     "index: 1"),
    ("duplicate partition", lambda d: d["partitions"][1].update(name="io"),
     "partitions[1].name: 'io' is already the name of partitions[0]", "name: io"),
    ("duplicate port", lambda d: d["partitions"][1]["ports"][1].update(name="GPS_IN"),
     "partitions[1].ports[1].name: 'GPS_IN' is already the name of a port of this partition",
     "GPS_IN"),
    ("names differing in case",
     lambda d: d["partitions"][1]["ports"][1].update(name="Gps_In"),
     "partitions[1].ports[1].name: 'Gps_In' and the port 'GPS_IN' differ only in case: their "
     "C glue would have the same names", "Gps_In"),
    ("reserved name", lambda d: d["partitions"][0]["processes"][1].update(name="count"),
     "partitions[0].processes[1].name: 'count' is reserved: the C glue counts the processes "
     "as <PARTITION>_PROCESS_COUNT", "name: count"),
    ("partition named like the application", lambda d: d["partitions"][1].update(name="RPAS"),
     "partitions[1].name: 'RPAS' is the application's name", "name: RPAS"),
    ("refresh on a queuing port",
     lambda d: d["partitions"][0]["ports"].append(
         {"name": "Q", "direction": "source", "kind": "queuing", "size": 8, "max_messages": 4,
          "refresh_s": 0.1}),
     "partitions[0].ports[13].refresh_s: only a sampling port has a refresh period",
     "refresh_s: 0.1"),
    ("unknown channel port",
     lambda d: d["channels"]["intra_node"][0].update({"from": "io.GPS_OUTX"}),
     "channels.intra_node[0].from: partition 'io' has no port named 'GPS_OUTX' (its ports: "
     "GPS_OUT, ", "io.GPS_OUTX"),
    ("unknown channel partition", lambda d: d["channels"]["intra_node"][1].update(to="nav.AHRS_IN"),
     "channels.intra_node[1].to: no partition named 'nav' "
     "(partitions: io, nav_fcs, fdr, mission_manager)",
     "nav.AHRS_IN"),
    ("source is a destination port",
     lambda d: d["channels"]["intra_node"][0].update({"from": "nav_fcs.MISSION_IN"}),
     "channels.intra_node[0].from: nav_fcs.MISSION_IN is a destination port: a channel's "
     "source must be a source port", "MISSION_IN"),
    ("destination is a source port",
     lambda d: d["channels"]["intra_node"][0].update(to="nav_fcs.NAV_OUT"),
     "channels.intra_node[0].to: nav_fcs.NAV_OUT is a source port: a channel's destination "
     "must be a destination port", "NAV_OUT"),
    ("sizes differ", lambda d: d["partitions"][1]["ports"][0].update(size=32),
     "channels.intra_node[0].to: nav_fcs.GPS_IN has size 32 but the source io.GPS_OUT has 64",
     "to: nav_fcs.GPS_IN"),
    ("port on two channels",
     lambda d: d["channels"]["intra_node"][1].update(to="nav_fcs.GPS_IN"),
     "channels.intra_node[1].to: nav_fcs.GPS_IN is already an end of channels.intra_node[0] "
     "(gps): a port belongs to one channel", "to: nav_fcs.GPS_IN"),
    ("windows overlap", lambda d: window(d, 1).update(start_s=0.004),
     "schedule.windows[1]: window of 'nav_fcs' [0.004 s, 0.019 s) overlaps schedule.windows[0] "
     "of 'io' [0.0 s, 0.005 s)", "partition: nav_fcs"),
    ("window past the major frame", lambda d: window(d, 2).update(start_s=0.048),
     "schedule.windows[2]: window of 'io' runs from 0.048 s to 0.053 s, past the major frame "
     "of 0.05 s", "partition: io"),
    ("window of an unknown partition", lambda d: window(d, 1).update(partition="fcs"),
     "schedule.windows[1].partition: no partition named 'fcs'", "partition: fcs"),
    ("partition without a window", lambda d: d["schedule"]["windows"].pop(1),
     "partitions[1]: partition 'nav_fcs' has no window in schedule.windows", "name: nav_fcs"),
    ("period does not divide the frame", lambda d: d["partitions"][1].update(period_s=0.03),
     "partitions[1].period_s: 0.03 does not divide the major frame (0.05 s)", "period_s: 0.03"),
    ("process period", lambda d: d["partitions"][0]["processes"][0].update(period_s=0.07),
     "partitions[0].processes[0].period_s: 0.07 is not a multiple of the partition period",
     "period_s: 0.07"),
    ("more than nanoseconds", lambda d: d["schedule"].update(major_frame_s=0.0500000001),
     "schedule.major_frame_s: 0.0500000001 is not a whole number of nanoseconds",
     "major_frame_s"),
    ("replicated partition unknown", lambda d: d.update(replicated=["fcs"]),
     "replicated[0]: no partition named 'fcs' (partitions: io, nav_fcs, fdr, mission_manager)",
     "- fcs"),
    ("process level during initialisation",
     lambda d: d["health_monitoring"]["system"]["PARTITION_INIT"].update(
         NUMERIC_ERROR="PROCESS"),
     "health_monitoring.system.PARTITION_INIT.NUMERIC_ERROR: PROCESS level needs a process "
     "whose error handler could act: in state PARTITION_INIT no ARINC process runs",
     "NUMERIC_ERROR: PROCESS"),
    ("unknown CAN message",
     lambda d: d["channels"]["can"]["partitions"]["io"]["receives"].append("GPS_SPEED"),
     "channels.can.partitions.io.receives[15]: 'GPS_SPEED' (node1) is not a message of rpas.dbc",
     "GPS_SPEED"),
    ("sending on every channel",
     lambda d: d["channels"]["can"]["partitions"]["io"]["sends"].append("NAV_POS_{channels}"),
     "channels.can.partitions.io.sends[6]: 'NAV_POS_{channels}': a node sends on its own "
     "redundancy channel only: use {channel}", "NAV_POS_{channels}"),
    ("CAN traffic of an unknown partition",
     lambda d: d["channels"]["can"]["partitions"].update(mm={"sends": ["GPS_POS"]}),
     "channels.can.partitions.mm: no partition named 'mm'", "mm:"),
    ("heartbeat not in the DBC", lambda d: d["membership"].update(heartbeat="FCS_HB"),
     "membership.heartbeat: no message FCS_HB_A (node1's heartbeat on channel A) in rpas.dbc",
     "heartbeat: FCS_HB"),
    ("DDS topic twice",
     lambda d: d["channels"]["dds"]["topics"][1].update(name="rpas_CrossChannelInputs"),
     "channels.dds.topics[1].name: 'rpas_CrossChannelInputs' is listed twice",
     "rpas_CrossChannelInputs"),
    ("vote after the frame", lambda d: d["voting"].update(offset_s=0.05),
     "voting.offset_s: 0.05 is not within the major frame (0.05 s)", "offset_s: 0.05"),
    ("not a finite number",
     lambda d: d["voting"]["thresholds"].update(elev=float("nan")),
     "voting.thresholds.elev: nan is not a finite number", "elev: .nan"),
    ("missing DDS configuration", lambda d: d["channels"]["dds"].update(config="dds.xml"),
     "channels.dds.config: no such file: ", "config: dds.xml"),
    ("missing DBC", lambda d: d["channels"]["can"].update(dbc="no/such.dbc"),
     "channels.can.dbc: no such file: ", "dbc: no/such.dbc"),
]


@pytest.mark.parametrize(("edit", "expected", "on_line"), [c[1:] for c in SEMANTIC_CASES],
                         ids=[c[0] for c in SEMANTIC_CASES])
def test_semantic_errors_name_the_path_and_line(tmp_path, good, edit, expected,
                                                on_line) -> None:
    msg, lines = refuse(tmp_path, good, edit)
    assert f": {expected}" in msg, msg
    assert on_line in lines[line_of(msg) - 1], (msg, lines[line_of(msg) - 1])


def test_a_replica_frame_must_be_on_its_channel(tmp_path, good) -> None:
    """A {channel} message whose identifier says another redundancy channel is refused."""
    dbc = (ROOT / "config" / "can" / "rpas.dbc").read_text()
    # Swap the identifiers of ACT_CMD_A and ACT_CMD_B.
    swapped = (dbc.replace("2295858752", "X").replace("2295858753", "2295858752")
               .replace("X", "2295858753"))
    (tmp_path / "swapped.dbc").write_text(swapped)
    msg, _ = refuse(tmp_path, good,
                    lambda d: d["channels"]["can"].update(dbc=str(tmp_path / "swapped.dbc")))
    assert ": channels.can.partitions.io.sends[0]: 'ACT_CMD_A' has redundancy channel 1 in " \
           "its identifier 0x08D80641, not 0 (node1, channel A)" in msg, msg
