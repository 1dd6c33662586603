# SPDX-License-Identifier: Apache-2.0
"""Remote pilot station scripts: load and validate the YAML, and what the pilot commands when."""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass, field
from pathlib import Path

from ima import schema_memo, yamlfile
from ima.errors import ImaError

MODES = ("DIRECT", "AUTOPILOT", "MISSION")
MODE_CODES = {"NONE": 0, "DIRECT": 1, "AUTOPILOT": 2, "MISSION": 3}
LAT_MODE_CODES = {"HDG": 0, "TRK": 1}
VERT_MODE_CODES = {"ALT": 0, "VS": 1}

_num = {"type": "number"}
_unit = {"type": "number", "minimum": -1, "maximum": 1}

SCHEMA = {
    "type": "object",
    "additionalProperties": False,
    "required": ["start"],
    "properties": {
        "description": {"type": "string"},
        "duration_s": {"type": "number", "exclusiveMinimum": 0},
        "start": {
            "type": "object",
            "additionalProperties": False,
            "required": ["altitude_ft", "airspeed_kt", "heading_deg"],
            "properties": {
                "lat_deg": {"type": "number", "minimum": -89, "maximum": 89},
                "lon_deg": {"type": "number", "minimum": -180, "maximum": 180},
                "altitude_ft": {"type": "number", "minimum": -1000, "maximum": 15000},
                "airspeed_kt": {"type": "number", "minimum": 60, "maximum": 140},
                "heading_deg": {"type": "number", "minimum": 0, "maximum": 360},
            },
        },
        "wind": {
            "type": "object",
            "additionalProperties": False,
            "properties": {
                "speed_kt": {"type": "number", "minimum": 0, "maximum": 100},
                "from_deg": {"type": "number", "minimum": 0, "maximum": 360},
            },
        },
        "turbulence": {"enum": ["none", "light", "moderate"]},
        # augmented GPS (SBAS- or GBAS-grade): smaller errors, reported in GPS_FIX
        "gps_augmentation": {"enum": ["none", "sbas", "gbas"]},
        # scripted intruders, reported by the surveillance receiver (traffic.py)
        "traffic": {
            "type": "array",
            "items": {
                "type": "object",
                "additionalProperties": False,
                "required": ["t", "bearing_deg", "range_m", "track_deg", "gs_kt"],
                "properties": {
                    "name": {"type": "string", "pattern": "^[A-Za-z0-9_-]{1,15}$"},
                    "t": {"type": "number", "minimum": 0},
                    "until": {"type": "number", "minimum": 0},
                    "bearing_deg": {"type": "number", "minimum": 0, "maximum": 360},
                    "range_m": {"type": "number", "exclusiveMinimum": 0, "maximum": 50000},
                    "rel_alt_ft": {"type": "number", "minimum": -5000, "maximum": 5000},
                    "track_deg": {"type": "number", "minimum": 0, "maximum": 360},
                    "gs_kt": {"type": "number", "minimum": 0, "maximum": 500},
                },
            },
        },
        # the remote pilot model flies DIRECT when the script does not (pilot_model.py)
        "pilot_model": {"type": "boolean"},
        "events": {
            "type": "array",
            "items": {
                "type": "object",
                "additionalProperties": False,
                "required": ["t"],
                "properties": {
                    "t": {"type": "number", "minimum": 0},
                    "mode": {"enum": list(MODES)},
                    "lat_mode": {"enum": list(LAT_MODE_CODES)},
                    "vert_mode": {"enum": list(VERT_MODE_CODES)},
                    "heading_deg": {"type": "number", "minimum": 0, "maximum": 360},
                    "altitude_ft": {"type": "number", "minimum": -1000, "maximum": 60000},
                    "airspeed_kt": {"type": "number", "minimum": 0, "maximum": 300},
                    "vs_fpm": {"type": "number", "minimum": -10000, "maximum": 10000},
                    "stick": {
                        "type": "object",
                        "additionalProperties": False,
                        "properties": {
                            "pitch": _unit, "roll": _unit, "yaw": _unit,
                            "throttle": {"type": "number", "minimum": 0, "maximum": 1},
                        },
                    },
                    "c2_link": {"enum": ["up", "down"]},
                    # the station's uplink of mission plans: `corrupt` flips a bit of every
                    # segment it sends (a plan's CRC then fails), until `ok`
                    "uplink": {"enum": ["ok", "corrupt"]},
                    # a mission command the station uplinks (the mission manager acts on it)
                    "mission": {"oneOf": [
                        {"enum": ["engage", "pause", "resume"]},
                        {"type": "object", "additionalProperties": False,
                         "required": ["direct_to"],
                         "properties": {"direct_to": {"type": "integer", "minimum": 0,
                                                      "maximum": 254}}}]},
                    "gps": {"enum": ["ok", "lost", "frozen"]},
                    "wind": {"$ref": "#/properties/wind"},
                },
            },
        },
        "evaluate": {
            "type": "object",
            "additionalProperties": False,
            "properties": {"settle_s": {"type": "number", "minimum": 0}},
        },
    },
}

TARGET_KEYS = ("lat_mode", "vert_mode", "heading_deg", "altitude_ft", "airspeed_kt", "vs_fpm")


class PilotScriptError(ImaError):
    """A pilot script that cannot be read or breaks the schema (message names file and path)."""

    def __init__(self, message: str) -> None:
        super().__init__(message, exit_code=2)


def _path(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "(top level)"


@dataclass
class PilotScript:
    """A loaded script. `state(t)` is what the station commands at time t (seconds)."""

    path: str
    start: dict
    events: list[dict]
    settle_s: float | None = None
    wind: dict | None = None
    turbulence: str | None = None
    duration_s: float | None = None
    description: str = ""
    pilot_model: bool = True
    traffic: list[dict] = field(default_factory=list)
    gps_augmentation: str = "none"
    initial: dict = field(default_factory=dict)

    @property
    def has_mission(self) -> bool:
        """The script sends mission commands."""
        return any("mission" in e for e in self.events)

    def __post_init__(self) -> None:
        s = self.start
        self.initial = {
            "mode": "AUTOPILOT", "lat_mode": "HDG", "vert_mode": "ALT",
            "heading_deg": s["heading_deg"], "altitude_ft": s["altitude_ft"],
            "airspeed_kt": s["airspeed_kt"], "vs_fpm": 0.0,
            "stick": {"pitch": 0.0, "roll": 0.0, "yaw": 0.0, "throttle": None},
            "c2_link": "up", "gps": "ok", "uplink": "ok", "wind": None,
        }

    @staticmethod
    def apply(state: dict, event: dict) -> dict:
        """The station state after one event (fields not in the event are kept)."""
        new = dict(state)
        for k, v in event.items():
            if k in ("t", "mission"):  # a mission command is an instant, not a state
                continue
            if k == "stick":
                new["stick"] = {**state["stick"], **v}
            else:
                new[k] = v
        return new

    def state(self, t_s: float) -> dict:
        st = self.initial
        for e in self.events:
            if e["t"] > t_s:
                break
            st = self.apply(st, e)
        return st

    def segments(self, end_s: float) -> list[tuple[float, float, dict]]:
        """Piecewise-constant station state [(t0, t1, state)] over [0, end_s)."""
        out = []
        st, t0 = self.initial, 0.0
        for e in self.events:
            if e["t"] >= end_s:
                break
            if e["t"] > t0:
                out.append((t0, float(e["t"]), st))
                t0 = float(e["t"])
            st = self.apply(st, e)
        if end_s > t0:
            out.append((t0, float(end_s), st))
        return out

    def autopilot_segments(self, end_s: float) -> list[tuple[float, float, dict]]:
        """[(t0, t1, targets)] while the pilot asks for AUTOPILOT, adjacent equal ones merged.

        targets: lat_mode, vert_mode, heading_deg, altitude_ft, airspeed_kt, vs_fpm, c2_link.
        """
        out: list[tuple[float, float, dict]] = []
        for t0, t1, st in self.segments(end_s):
            if st["mode"] != "AUTOPILOT":
                continue
            tg = {k: st[k] for k in TARGET_KEYS}
            tg["c2_link"] = st["c2_link"]
            if out and out[-1][1] == t0 and out[-1][2] == tg:
                out[-1] = (out[-1][0], t1, tg)
            else:
                out.append((t0, t1, tg))
        return out


@functools.cache
def _schema_text() -> bytes:
    return json.dumps(SCHEMA, sort_keys=True).encode()


def _validate(doc, path: str) -> None:
    """Against SCHEMA (a script found valid before is not validated again: ima.schema_memo)."""
    if schema_memo.known_valid(_schema_text(), doc):
        return
    import jsonschema

    v = jsonschema.Draft202012Validator(SCHEMA)
    errors = sorted(v.iter_errors(doc), key=lambda e: (list(map(str, e.absolute_path)), e.message))
    if errors:
        lines = [f"{_path(e.absolute_path)}: {e.message}" for e in errors[:5]]
        more = f" (and {len(errors) - 5} more)" if len(errors) > 5 else ""
        raise PilotScriptError(f"{path}: bad pilot script: " + "; ".join(lines) + more)
    schema_memo.remember_valid(_schema_text(), doc)


def parse(doc, path: str = "<script>") -> PilotScript:
    """Validate a parsed YAML document and build the script; PilotScriptError if it is bad."""
    bad = yamlfile.first_not_finite(doc)
    if bad is not None:
        where, val = bad
        raise PilotScriptError(f"{path}: {_path(where)}: {val} is not a finite number")
    _validate(doc, path)
    events = [dict(e) for e in doc.get("events") or []]
    for i in range(1, len(events)):
        if events[i]["t"] < events[i - 1]["t"]:
            raise PilotScriptError(f"{path}: events[{i}].t: {events[i]['t']} comes before the "
                                   f"previous event's t ({events[i - 1]['t']}); keep events in "
                                   "time order")
    start = dict(doc["start"])
    start.setdefault("lat_deg", 47.0)
    start.setdefault("lon_deg", 8.0)
    return PilotScript(
        path=path, start=start, events=events,
        settle_s=(doc.get("evaluate") or {}).get("settle_s"),
        wind=doc.get("wind"), turbulence=doc.get("turbulence"),
        duration_s=doc.get("duration_s"), description=doc.get("description", ""),
        pilot_model=doc.get("pilot_model", True), traffic=list(doc.get("traffic") or []),
        gps_augmentation=doc.get("gps_augmentation", "none"))


def load(path: str | Path) -> PilotScript:
    """Load and validate a pilot script file."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as e:
        raise PilotScriptError(f"{path}: cannot read the pilot script: {e.strerror}") from e
    except UnicodeDecodeError as e:
        raise PilotScriptError(f"{path}: not a text file in UTF-8 (byte {e.start}: "
                               f"{e.reason})") from e
    return parse(yamlfile.load_document(text, path, PilotScriptError), str(path))
