# SPDX-License-Identifier: Apache-2.0
"""The system a MISSION workload flies: the campaign's system model with the stand-in mission
feed (partition `mission_feed`, partitions/testing/) in place of the mission manager, writing
fixed MISSION targets to nav_fcs (a workload flies no plan). Written into the campaign folder,
generated from the model (never edited), so the one source of truth stays the model."""

from __future__ import annotations

from pathlib import Path

import yaml

from ima.deploy.source import read_source

FEED_WINDOW = {"partition": "mission_feed", "start_s": 0.03, "duration_s": 0.005}


def _absolute(doc: dict, base_of) -> None:
    """Paths written in the model, made absolute (the derived file lives elsewhere)."""
    ch = doc.get("channels", {})
    for section, key in (("can", "dbc"), ("dds", "config")):
        if section in ch and key in ch[section] and not Path(ch[section][key]).is_absolute():
            ch[section][key] = str((base_of("channels") / ch[section][key]).resolve())


def drop_partition(doc: dict, name: str) -> None:
    """Removes partition `name` from a system or application document: the partition, its
    windows, and its ends of the intra-node channels (a channel left with no end goes too)."""
    doc["partitions"] = [p for p in doc["partitions"] if p["name"] != name]
    doc["schedule"] = dict(doc["schedule"], windows=[
        w for w in doc["schedule"]["windows"] if w["partition"] != name])
    kept = []
    for ch in doc["channels"].get("intra_node") or []:
        if ch["from"].split(".")[0] == name:
            continue
        to = ch["to"] if isinstance(ch["to"], list) else [ch["to"]]
        to = [t for t in to if t.split(".")[0] != name]
        if to:
            kept.append(dict(ch, to=to if len(to) > 1 else to[0]))
    doc["channels"] = dict(doc["channels"], intra_node=kept)


def with_mission_feed(system: Path, dest: Path, feed: dict) -> Path:
    """dest: the system with the mission feed (feed: heading_deg, altitude_ft, airspeed_kt,
    silent_after_s)."""
    source = read_source(Path(system))
    doc = dict(source.doc)
    _absolute(doc, source.base)
    drop_partition(doc, "mission_manager")
    silent = feed.get("silent_after_s", 1e6)
    doc["partitions"] = list(doc["partitions"]) + [{
        "name": "mission_feed", "criticality": "LEVEL_C", "personality": "apex-c",
        "executable": "mission_feed",
        "arguments": [f"{feed['heading_deg']:g}", f"{feed['altitude_ft']:g}",
                      f"{feed['airspeed_kt']:g}", f"{silent:g}"],
        "period_s": 0.05,
        "processes": [{"name": "feed", "period_s": 0.05, "stack": 65536, "priority": 10}],
        "ports": [{"name": "MISSION_OUT", "direction": "source", "kind": "sampling",
                   "size": 56, "refresh_s": 0.5, "message": "rpas_mission_msg_t"},
                  # its log, a queuing channel to itself (a target for queuing faults)
                  {"name": "FEED_LOG_OUT", "direction": "source", "kind": "queuing",
                   "size": 8, "max_messages": 8},
                  {"name": "FEED_LOG_IN", "direction": "destination", "kind": "queuing",
                   "size": 8, "max_messages": 8}],
        "memory": [{"type": "DATA", "size": 0x2000000, "access": "READ_WRITE"}]}]
    doc["schedule"] = dict(doc["schedule"], windows=list(doc["schedule"]["windows"]) +
                           [FEED_WINDOW])
    # the targets go to nav_fcs, and to every other partition that takes them (the flight
    # data recorder records them)
    takers = [f"{p['name']}.MISSION_IN" for p in doc["partitions"]
              if any(q["name"] == "MISSION_IN" and q["direction"] == "destination"
                     for q in p.get("ports") or [])]
    doc["channels"] = dict(doc["channels"], intra_node=list(doc["channels"]["intra_node"]) + [
        {"name": "mission", "from": "mission_feed.MISSION_OUT", "to": takers},
        {"name": "feed_log", "from": "mission_feed.FEED_LOG_OUT",
         "to": "mission_feed.FEED_LOG_IN"}])
    dest.parent.mkdir(parents=True, exist_ok=True)
    header = (f"# Generated from {system} with the stand-in mission feed — do not edit.\n"
              "# SPDX-License-Identifier: Apache-2.0\n")
    dest.write_text(header + yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return dest
