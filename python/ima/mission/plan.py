# SPDX-License-Identifier: Apache-2.0
"""A mission plan (config/missions/*.yaml, config/schema/mission.schema.json): read within
ima.yamlfile's bounds, validated against the schema, then checked for what a schema cannot say
(names that exist and are unique, the order of the legs, the contingencies' actions, the size
of the image, and, through ima.mission.geometry, a path the aircraft can fly). Every error is
one line naming the file and the path of the bad value."""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import jsonschema

from ima import paths, yamlfile
from ima.errors import ImaError

MAX_LEGS = 48  # RPAS_PLAN_MAX_LEGS: the mission's legs and every procedure's
MAX_RANGE_KM = 100.0  # the local frame is flat: a plan stays this close to its origin
MAX_FILE_BYTES = 1_000_000

# In the order of enum rpas_contingency (rpas_plan_header_t.contingency[]).
CONTINGENCIES = ("c2_loss", "gps_loss", "traffic", "autopilot_disengage", "flight_termination")
ACTIONS = ("procedure", "hold", "avoid", "terminate")

LIMIT_DEFAULTS = {"min_airspeed_kt": 65.0, "max_airspeed_kt": 125.0, "max_bank_deg": 25.0,
                  "max_vs_fpm": 800.0}
SEPARATION_DEFAULTS = {"horizontal_m": 1000.0, "vertical_ft": 500.0}
RUNWAY_DEFAULTS = {"width_m": 30.0, "glide_path_deg": 3.0, "aim_point_m": 300.0}

# Legs that end over their fix (the next leg's origin is that fix).
ENDS_AT_FIX = ("IF", "TF", "DF", "CF", "RF", "DIRECT", "DUBINS", "HA", "HF", "HM")

# The YAML names that all land in Leg.course_deg (the image's course_deg) and Leg.turn.
_COURSE_KEYS = ("course_deg", "inbound_course_deg", "heading_deg", "direction_deg")
_TURN_KEYS = ("turn", "side")


class MissionPlanError(ImaError):
    """A plan that cannot be read or is wrong: one line naming the file and the bad value."""

    def __init__(self, message: str) -> None:
        super().__init__(message, exit_code=2)


@dataclass(frozen=True)
class Waypoint:
    name: str
    lat_deg: float
    lon_deg: float


@dataclass(frozen=True)
class Runway:
    name: str
    lat_deg: float  # the threshold
    lon_deg: float
    elevation_ft: float
    heading_deg: float
    length_m: float
    width_m: float
    glide_path_deg: float
    aim_point_m: float


@dataclass(frozen=True)
class Leg:
    """One leg, as the YAML gives it; `where` is its path in the file (legs[3],
    contingencies.c2_loss.procedure[0]). course_deg holds the course of CF, CA, FA and DUBINS,
    the heading of VA, the inbound course of a hold and the direction of a SCAN's first pass;
    turn holds the turn of RF, holds and orbits and the side of a SCAN."""

    type: str
    where: str
    fix: str | None = None
    course_deg: float | None = None
    altitude_ft: float | None = None
    airspeed_kt: float | None = None
    fly_over: bool = False
    geometric: bool = False
    turn: str | None = None
    center: str | None = None
    runway: str | None = None
    leg_time_s: float | None = None
    laps: int | None = None
    time_s: float | None = None
    radius_m: float | None = None
    length_m: float | None = None
    spacing_m: float | None = None
    passes: int | None = None


@dataclass(frozen=True)
class Contingency:
    name: str  # one of CONTINGENCIES
    action: str  # one of ACTIONS
    detect_s: float
    continue_s: float | None = None  # procedure, hold
    resume: bool = False
    procedure: tuple[Leg, ...] = ()
    offset_deg: float | None = None  # avoid
    altitude_offset_ft: float | None = None  # avoid


@dataclass(frozen=True)
class Limits:
    min_airspeed_kt: float
    max_airspeed_kt: float
    max_bank_deg: float
    max_vs_fpm: float


@dataclass(frozen=True)
class Plan:
    path: str
    name: str
    description: str
    plan_id: int
    origin_lat_deg: float
    origin_lon_deg: float
    cruise_airspeed_kt: float
    cruise_altitude_ft: float
    limits: Limits
    traffic_h_m: float
    traffic_v_ft: float
    waypoints: dict[str, Waypoint]
    runways: dict[str, Runway]
    legs: tuple[Leg, ...]
    contingencies: dict[str, Contingency] = field(default_factory=dict)  # CONTINGENCIES order

    def image_legs(self) -> list[tuple[Leg, str | None]]:
        """Every leg in the image's order: the mission's, then each procedure's (with the
        contingency it belongs to; None for the mission)."""
        out: list[tuple[Leg, str | None]] = [(leg, None) for leg in self.legs]
        for c in self.contingencies.values():
            out += [(leg, c.name) for leg in c.procedure]
        return out


@functools.cache
def schema() -> dict:
    return json.loads((paths.repo_root() / "config" / "schema" / "mission.schema.json")
                      .read_text(encoding="utf-8"))


def path_text(parts) -> str:
    """A value's path as the errors name it: legs[3].fix."""
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "(top level)"


def _schema_message(e: jsonschema.ValidationError) -> str:
    if e.validator == "additionalProperties" and isinstance(e.instance, dict):
        allowed = list(e.schema.get("properties", {}))
        extra = [k for k in e.instance if k not in allowed]
        kind = f"of a {e.instance['type']} leg" if "type" in allowed and "type" in e.instance \
            else "here"
        return (f"{', '.join(repr(k) for k in extra)} "
                f"{'is not a field' if len(extra) == 1 else 'are not fields'} {kind} "
                f"(fields: {', '.join(k for k in allowed if k != 'type')})")
    if e.validator == "pattern" and e.schema.get("description"):
        return f"{e.message} (expected {e.schema['description']})"
    return e.message


def _schema_error(doc) -> str | None:
    """The first schema error in document order, as `PATH: MESSAGE`."""
    validator = jsonschema.Draft202012Validator(schema())
    found = [jsonschema.exceptions.best_match([e]) for e in validator.iter_errors(doc)]
    if not found:
        return None

    def key(e):
        return [(0, p, "") if isinstance(p, int) else (1, 0, str(p)) for p in e.absolute_path]

    found.sort(key=key)
    first = found[0]
    more = f" (and {len(found) - 1} more)" if len(found) > 1 else ""
    return f"{path_text(first.absolute_path)}: {_schema_message(first)}{more}"


def _names(names) -> str:
    names = list(names)
    return ", ".join(names[:12]) + (", ..." if len(names) > 12 else "") if names else "none"


def _float(value) -> float | None:
    return None if value is None else float(value)


def _leg(doc: dict, where: str) -> Leg:
    course = next((doc[k] for k in _COURSE_KEYS if k in doc), None)
    turn = next((doc[k] for k in _TURN_KEYS if k in doc), None)

    def num(key):
        return _float(doc.get(key))

    return Leg(type=doc["type"], where=where, fix=doc.get("fix"),
               course_deg=_float(course),
               altitude_ft=num("altitude_ft"), airspeed_kt=num("airspeed_kt"),
               fly_over=bool(doc.get("fly_over", False)),
               geometric=doc.get("path") == "geometric", turn=turn, center=doc.get("center"),
               runway=doc.get("runway"), leg_time_s=num("leg_time_s"), laps=doc.get("laps"),
               time_s=num("time_s"), radius_m=num("radius_m"), length_m=num("length_m"),
               spacing_m=num("spacing_m"), passes=doc.get("passes"))


class _Checker:
    """The rules beyond the schema; `fail` makes the one-line error."""

    def __init__(self, path: str, doc: dict) -> None:
        self.path = path
        self.doc = doc

    def fail(self, where: str, message: str) -> MissionPlanError:
        return MissionPlanError(f"{self.path}: {where}: {message}")

    def waypoints(self) -> dict[str, Waypoint]:
        out: dict[str, Waypoint] = {}
        for i, w in enumerate(self.doc["waypoints"]):
            if w["name"] in out:
                raise self.fail(f"waypoints[{i}].name", f"'{w['name']}' names an earlier "
                                "waypoint already")
            out[w["name"]] = Waypoint(w["name"], float(w["lat_deg"]), float(w["lon_deg"]))
        return out

    def runways(self, waypoints: dict[str, Waypoint]) -> dict[str, Runway]:
        out: dict[str, Runway] = {}
        for i, r in enumerate(self.doc.get("runways") or []):
            if r["name"] in out or r["name"] in waypoints:
                what = "an earlier runway" if r["name"] in out else "a waypoint"
                raise self.fail(f"runways[{i}].name", f"'{r['name']}' names {what} already")
            v = {**RUNWAY_DEFAULTS, **r}
            if v["aim_point_m"] >= v["length_m"]:
                raise self.fail(f"runways[{i}].aim_point_m", f"{v['aim_point_m']} m is not on "
                                f"the runway ({v['length_m']} m long)")
            out[r["name"]] = Runway(r["name"], float(r["threshold"]["lat_deg"]),
                                    float(r["threshold"]["lon_deg"]), float(v["elevation_ft"]),
                                    float(v["heading_deg"]) % 360.0, float(v["length_m"]),
                                    float(v["width_m"]), float(v["glide_path_deg"]),
                                    float(v["aim_point_m"]))
        return out

    def in_range(self, origin: tuple[float, float], where: str, lat: float, lon: float) -> None:
        from ima.mission.geometry import Frame

        n, e = Frame(*origin).to_local(lat, lon)
        km = math.hypot(n, e) / 1000.0
        if km > MAX_RANGE_KM:
            raise self.fail(where, f"{km:.1f} km from the origin: the plan's local frame is "
                            f"flat, keep every position within {MAX_RANGE_KM:.0f} km of it")

    def limits(self) -> Limits:
        lim = Limits(**{k: float(v) for k, v in
                        {**LIMIT_DEFAULTS, **(self.doc.get("limits") or {})}.items()})
        if lim.min_airspeed_kt >= lim.max_airspeed_kt:
            raise self.fail("limits.min_airspeed_kt", f"{lim.min_airspeed_kt:g} kt is not below "
                            f"max_airspeed_kt ({lim.max_airspeed_kt:g} kt)")
        return lim

    def airspeed(self, where: str, kt: float | None, lim: Limits) -> None:
        if kt is not None and not lim.min_airspeed_kt <= kt <= lim.max_airspeed_kt:
            raise self.fail(where, f"{kt:g} kt is outside the envelope "
                            f"{lim.min_airspeed_kt:g}..{lim.max_airspeed_kt:g} kt (limits)")

    def references(self, leg: Leg, waypoints: dict, runways: dict, lim: Limits) -> None:
        for key in ("fix", "center"):
            name = getattr(leg, key)
            if name is not None and name not in waypoints:
                raise self.fail(f"{leg.where}.{key}", f"'{name}' is not a waypoint "
                                f"(waypoints: {_names(waypoints)})")
        if leg.runway is not None and leg.runway not in runways:
            raise self.fail(f"{leg.where}.runway", f"'{leg.runway}' is not a runway "
                            f"(runways: {_names(runways)})")
        if leg.type == "RF" and leg.center == leg.fix:
            raise self.fail(f"{leg.where}.center", "the arc's centre is its own fix")
        if leg.type == "ORBIT" and (leg.laps is None) == (leg.time_s is None):
            raise self.fail(leg.where, "an ORBIT needs laps or time_s (one of them)")
        self.airspeed(f"{leg.where}.airspeed_kt", leg.airspeed_kt, lim)

    def order(self, legs: list[Leg], procedure: str | None) -> None:
        """The mission starts at its IF; a procedure starts from wherever the aircraft is;
        an AUTOLAND ends what it is in."""
        for i, leg in enumerate(legs):
            if leg.type == "IF" and (procedure is not None or i > 0):
                raise self.fail(f"{leg.where}.type", "IF starts the mission and nothing else "
                                "(a procedure starts from where the aircraft is)")
            if leg.type == "AUTOLAND" and i < len(legs) - 1:
                raise self.fail(legs[i + 1].where, f"follows the AUTOLAND of {leg.where}, "
                                "which ends the " + ("procedure" if procedure else "mission"))
        if procedure is None and legs[0].type != "IF":
            raise self.fail("legs[0].type", f"'{legs[0].type}': a mission starts with an IF leg "
                            "(its initial fix)")
        if procedure is not None and legs[0].type in ("TF", "RF"):
            raise self.fail(f"{legs[0].where}.type", "a procedure cannot start with "
                            f"{legs[0].type}: it starts from where the aircraft is (DF, DIRECT, "
                            "CA, VA, a hold, ...)")

    def contingency(self, name: str, c: dict) -> Contingency:
        where = f"contingencies.{name}"
        action = c.get("action") or ("procedure" if "procedure" in c else None)
        if action is None:
            raise self.fail(where, f"needs an action ({', '.join(ACTIONS)}) or a procedure")
        if action == "procedure" and "procedure" not in c:
            raise self.fail(where, "action 'procedure' needs a procedure (a list of legs)")
        if action != "procedure" and "procedure" in c:
            raise self.fail(f"{where}.procedure", f"only with action 'procedure' (this one is "
                            f"'{action}')")
        if action == "avoid" and name != "traffic":
            raise self.fail(f"{where}.action", "'avoid' is for traffic only")
        avoid_keys = [k for k in ("offset_deg", "altitude_offset_ft") if k in c]
        if action == "avoid" and len(avoid_keys) < 2:
            raise self.fail(where, "action 'avoid' needs offset_deg and altitude_offset_ft")
        if action != "avoid" and avoid_keys:
            raise self.fail(f"{where}.{avoid_keys[0]}", "only with action 'avoid'")
        if "continue_s" in c and action not in ("procedure", "hold"):
            raise self.fail(f"{where}.continue_s", "only with action 'procedure' or 'hold'")
        if action == "terminate" and c.get("resume"):
            raise self.fail(f"{where}.resume", "a flight termination does not resume")
        legs = tuple(_leg(leg, f"{where}.procedure[{i}]")
                     for i, leg in enumerate(c.get("procedure") or []))
        continue_s = c.get("continue_s", 0.0) if action in ("procedure", "hold") else None
        return Contingency(name=name, action=action, detect_s=float(c["detect_s"]),
                           continue_s=_float(continue_s),
                           resume=bool(c.get("resume", False)), procedure=legs,
                           offset_deg=_float(c.get("offset_deg")),
                           altitude_offset_ft=_float(c.get("altitude_offset_ft")))


def parse(doc, path: str = "<plan>") -> Plan:
    """Checks a parsed YAML document and builds the plan; MissionPlanError if it is wrong."""
    bad = yamlfile.first_not_finite(doc)
    if bad is not None:
        where, value = bad
        raise MissionPlanError(f"{path}: {path_text(where)}: {value} is not a finite number")
    error = _schema_error(doc)
    if error is not None:
        raise MissionPlanError(f"{path}: {error}")
    ck = _Checker(path, doc)
    waypoints = ck.waypoints()
    runways = ck.runways(waypoints)
    first = next(iter(waypoints.values()))
    o = doc.get("origin") or {"lat_deg": first.lat_deg, "lon_deg": first.lon_deg}
    origin = (float(o["lat_deg"]), float(o["lon_deg"]))
    for i, w in enumerate(waypoints.values()):
        ck.in_range(origin, f"waypoints[{i}]", w.lat_deg, w.lon_deg)
    for i, r in enumerate(runways.values()):
        ck.in_range(origin, f"runways[{i}].threshold", r.lat_deg, r.lon_deg)
    lim = ck.limits()
    ck.airspeed("cruise.airspeed_kt", float(doc["cruise"]["airspeed_kt"]), lim)
    legs = [_leg(leg, f"legs[{i}]") for i, leg in enumerate(doc["legs"])]
    ck.order(legs, None)
    contingencies = {name: ck.contingency(name, doc["contingencies"][name])
                     for name in CONTINGENCIES if name in (doc.get("contingencies") or {})}
    for c in contingencies.values():
        if c.procedure:
            ck.order(list(c.procedure), c.name)
    for leg in legs + [leg for c in contingencies.values() for leg in c.procedure]:
        ck.references(leg, waypoints, runways, lim)
    n_proc = sum(len(c.procedure) for c in contingencies.values())
    if len(legs) + n_proc > MAX_LEGS:
        raise MissionPlanError(f"{path}: legs: {len(legs) + n_proc} legs ({len(legs)} of the "
                               f"mission, {n_proc} of the procedures); an image holds "
                               f"{MAX_LEGS} at most")
    sep = {**SEPARATION_DEFAULTS, **(doc.get("traffic_separation") or {})}
    plan = Plan(path=path, name=doc["mission"], description=doc.get("description", ""),
                plan_id=int(doc["plan_id"]), origin_lat_deg=origin[0], origin_lon_deg=origin[1],
                cruise_airspeed_kt=float(doc["cruise"]["airspeed_kt"]),
                cruise_altitude_ft=float(doc["cruise"]["altitude_ft"]), limits=lim,
                traffic_h_m=float(sep["horizontal_m"]), traffic_v_ft=float(sep["vertical_ft"]),
                waypoints=waypoints, runways=runways, legs=tuple(legs),
                contingencies=contingencies)
    from ima.mission import geometry

    geometry.leg_paths(plan)  # refuses a path the aircraft cannot fly
    return plan


def load(path: str | Path) -> Plan:
    """Loads and checks a mission plan file; MissionPlanError naming the file and the path."""
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError as e:
        raise MissionPlanError(f"{path}: cannot read the mission plan: {e.strerror}") from e
    if len(data) > MAX_FILE_BYTES:
        raise MissionPlanError(f"{path}: refused: larger than {MAX_FILE_BYTES:,} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise MissionPlanError(f"{path}: not a text file in UTF-8 (byte {e.start}: "
                               f"{e.reason})") from e
    return parse(yamlfile.load_document(text, path, MissionPlanError), str(path))
