# SPDX-License-Identifier: Apache-2.0
"""`ima mission check | show | import`: checks mission plans (config/missions/*.yaml) and
prints their legs, contingencies and image; draws a plan's map and vertical profile; converts
a QGroundControl plan into a mission plan (docs/mission.md)."""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import zlib
from pathlib import Path

from ima.errors import ImaError

MAX_QGC_BYTES = 10_000_000
_QGC_COMMANDS = {16: "NAV_WAYPOINT", 17: "NAV_LOITER_UNLIM", 18: "NAV_LOITER_TURNS",
                 19: "NAV_LOITER_TIME", 21: "NAV_LAND", 22: "NAV_TAKEOFF"}


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "mission",
        help="check, draw or import mission plans (config/missions/*.yaml)",
        description="Mission plans: `check` validates plans and prints their legs, "
        "contingencies and binary image; `show` draws a plan's map and vertical profile; "
        "`import` converts a QGroundControl .plan file (docs/mission.md).",
    )
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    check = sub.add_parser(
        "check", help="validate plans; print each as a table of legs and contingencies",
        description="Validate each plan (schema, names, order of legs, a path the aircraft "
        "can fly, the image's size) and print its legs (index, type, fix, course, altitude, "
        "airspeed, flags, length), its contingencies and its image's size and CRC-32. "
        "Exit status 2 at the first broken plan, with one line naming the file and the bad "
        "value.")
    check.add_argument("files", metavar="FILE", nargs="+", type=Path, help="a mission plan")
    check.add_argument("--json", action="store_true",
                       help="each plan as one JSON object (one line per plan)")
    show = sub.add_parser(
        "show", help="draw a plan: the map and the vertical profile (PNG)",
        description="Draw a plan into a PNG: the map (east and north in km from the plan's "
        "origin, each leg labelled with its index and type, waypoints, runways) and the "
        "planned altitude along the mission. Prints the file written.")
    show.add_argument("file", metavar="FILE", type=Path, help="a mission plan")
    show.add_argument("-o", "--output", metavar="PNG", type=Path,
                      help="where to write (default: FILE's name with .png, here)")
    imp = sub.add_parser(
        "import", help="convert a QGroundControl .plan into a mission plan (YAML)",
        description="Convert a QGroundControl plan (its mission's simple items: takeoff, "
        "waypoints, loiters, land) into a mission plan, check it, and write it. Complex "
        "items (surveys, corridors, structure scans) are refused.")
    imp.add_argument("file", metavar="FILE.plan", type=Path, help="a QGroundControl plan")
    imp.add_argument("-o", "--output", metavar="YAML", type=Path,
                     help="where to write (default: FILE's name with .yaml, here)")
    imp.add_argument("--airspeed", type=float, default=100.0, metavar="KT",
                     help="the plan's cruise airspeed (default 100 kt)")
    imp.add_argument("--force", action="store_true", help="write over an existing file")
    return parser


def _fmt(v, spec: str = ".0f") -> str:
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "es" if noun.endswith("s") else "s")


def _detail(leg, path, plan) -> str:
    t = leg.type
    if t == "RF":
        return f"centre {leg.center}, r {path.radius_m:.0f} m"
    if t in ("HA", "HF", "HM"):
        if t == "HA":
            laps = f"until {leg.altitude_ft:g} ft ({path.laps} drawn)"
        elif t == "HF":
            laps = "1 circuit"
        else:
            laps = "until the pilot" if leg.laps == 0 else _count(leg.laps, "circuit")
        return f"{leg.leg_time_s:g} s legs, {laps}, r {path.radius_m:.0f} m"
    if t == "ORBIT":
        span = f"{leg.time_s:g} s" if leg.time_s is not None else \
            "until the pilot" if leg.laps == 0 else _count(leg.laps, "lap")
        return f"r {leg.radius_m:g} m, {span}"
    if t == "SCAN":
        return f"{_count(leg.passes, 'pass')} of {leg.length_m:g} m, {leg.spacing_m:g} m apart"
    if t == "DUBINS":
        return f"{path.word}, r {leg.radius_m:g} m"
    if t in ("CA", "FA", "VA"):
        return f"until {leg.altitude_ft:g} ft"
    if t == "AUTOLAND":
        rw = plan.runways[leg.runway]
        return (f"{rw.glide_path_deg:g}° to {rw.aim_point_m:g} m, {rw.length_m:g} x "
                f"{rw.width_m:g} m at {rw.elevation_ft:g} ft")
    return ""


def _rows(plan, paths) -> list[dict]:
    rows = []
    for (leg, part), path in zip(plan.image_legs(), paths, strict=True):
        flags = ["fly-over"] * leg.fly_over + ([leg.turn] if leg.turn else []) + \
            ["geometric"] * leg.geometric
        course = plan.runways[leg.runway].heading_deg if leg.type == "AUTOLAND" \
            else leg.course_deg
        rows.append({"index": path.index, "part": part or "mission", "type": leg.type,
                     "fix": leg.fix or leg.runway, "course_deg": course,
                     "altitude_ft": path.altitude_ft if leg.type == "AUTOLAND"
                     else leg.altitude_ft, "airspeed_kt": leg.airspeed_kt, "flags": flags,
                     "detail": _detail(leg, path, plan), "length_m": round(path.total_m, 1),
                     "duration_s": round(path.duration_s, 1)})
    return rows


def _contingencies(plan) -> dict:
    out, first = {}, len(plan.legs)
    for name, c in plan.contingencies.items():
        n = len(c.procedure)
        out[name] = {"action": c.action, "detect_s": c.detect_s, "continue_s": c.continue_s,
                     "resume": c.resume, "legs": [first, first + n - 1] if n else None,
                     "offset_deg": c.offset_deg, "altitude_offset_ft": c.altitude_offset_ft}
        first += n
    return out


def summary(path: Path) -> dict:
    """What `check --json` prints of one plan."""
    from ima.mission import geometry, image, plan

    p = plan.load(path)
    paths = geometry.leg_paths(p)
    img = image.encode(p)
    mission = [x for x in paths if x.procedure is None]
    return {"file": str(path), "mission": p.name, "plan_id": p.plan_id,
            "description": p.description, "legs": _rows(p, paths),
            "contingencies": _contingencies(p),
            "length_m": round(sum(x.total_m for x in mission), 1),
            "duration_s": round(sum(x.duration_s for x in mission), 1),
            "image": {"bytes": len(img), "crc32": f"0x{image.crc32(img):08x}"}}


def _print(s: dict, console) -> None:
    from rich.table import Table

    console.rule(f"{s['mission']} (plan {s['plan_id']}): {s['file']}")
    t = Table(show_edge=False)
    for col in ("#", "part", "type", "fix", "course", "alt ft", "speed kt", "flags", "detail",
                "length m"):
        t.add_column(col, justify="right" if col in ("#", "course", "alt ft", "speed kt",
                                                      "length m") else "left")
    for r in s["legs"]:
        t.add_row(str(r["index"]), r["part"], r["type"], r["fix"] or "-",
                  _fmt(r["course_deg"], "03.0f"), _fmt(r["altitude_ft"]),
                  _fmt(r["airspeed_kt"]), ", ".join(r["flags"]), r["detail"],
                  _fmt(r["length_m"]))
    console.print(t)
    if s["contingencies"]:
        c = Table(show_edge=False)
        for col in ("contingency", "action", "detect s", "continue s", "resume", "legs",
                    "avoid"):
            c.add_column(col)
        for name, v in s["contingencies"].items():
            avoid = "-" if v["offset_deg"] is None else \
                f"{v['offset_deg']:g}°, {v['altitude_offset_ft']:g} ft"
            legs = "-" if v["legs"] is None else f"{v['legs'][0]}–{v['legs'][1]}"
            c.add_row(name, v["action"], f"{v['detect_s']:g}", _fmt(v["continue_s"], "g"),
                      "yes" if v["resume"] else "no", legs, avoid)
        console.print(c)
    else:
        console.print("No contingencies declared.")
    console.print(f"Mission: {s['length_m'] / 1000:.1f} km, {s['duration_s'] / 60:.1f} min at "
                  "the planned airspeeds, no wind")
    console.print(f"image: {s['image']['bytes']} bytes, crc32 {s['image']['crc32']}")


def _check(args: argparse.Namespace) -> int:
    from rich.console import Console

    console = Console()
    if not console.is_terminal:  # a log file: wide enough for the table
        console = Console(width=140)
    for path in args.files:
        s = summary(path)
        if args.json:
            print(json.dumps(s))
        else:
            _print(s, console)
    return 0


def _show(args: argparse.Namespace) -> int:
    from ima.mission import geometry, plan, plot

    p = plan.load(args.file)
    paths = geometry.leg_paths(p)
    out = args.output or Path(args.file.stem + ".png")
    try:
        plot.plot(p, paths, geometry.vertical_profile(p, paths), out)
    except OSError as exc:
        raise ImaError(f"{out}: cannot write: {exc.strerror}") from exc
    print(out)
    return 0


# -- QGroundControl plans -----------------------------------------------------------------------

def _qgc_fail(src: str, where: str, message: str) -> ImaError:
    return ImaError(f"{src}: {where}: {message}", exit_code=2)


def _number(src: str, where: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise _qgc_fail(src, where, f"{v!r} is not a number")
    return float(v)


def _altitude_m(src: str, where: str, item: dict, home_alt_m: float) -> float:
    frame = item.get("frame")
    alt = item["params"][6] if item["params"][6] is not None else item.get("Altitude")
    if frame == 0:  # MAV_FRAME_GLOBAL: above mean sea level
        return _number(src, f"{where}.params[6]", alt)
    if frame == 3:  # MAV_FRAME_GLOBAL_RELATIVE_ALT: above home
        return _number(src, f"{where}.params[6]", alt) + home_alt_m
    if frame == 10 and item.get("AMSLAltAboveTerrain") is not None:  # above terrain
        return _number(src, f"{where}.AMSLAltAboveTerrain", item["AMSLAltAboveTerrain"])
    raise _qgc_fail(src, f"{where}.frame", f"{frame!r}: altitudes relative to home (3) or above "
                    "mean sea level (0) are converted, and above terrain (10) with its "
                    "AMSLAltAboveTerrain")


def convert_qgc(doc, src: str, airspeed_kt: float, plan_id: int) -> tuple[dict, list[str]]:
    """A QGroundControl plan as a mission plan document, and notes on what was changed."""
    from ima.mission import geometry
    from ima.mission.plan import LIMIT_DEFAULTS, RUNWAY_DEFAULTS

    mission = doc.get("mission") if isinstance(doc, dict) else None
    if not isinstance(mission, dict) or doc.get("fileType") != "Plan":
        raise _qgc_fail(src, "(top level)", "not a QGroundControl plan (fileType 'Plan' with "
                        "a mission)")
    home = mission.get("plannedHomePosition")
    if not isinstance(home, list) or len(home) != 3:
        raise _qgc_fail(src, "mission.plannedHomePosition", "missing: [lat, lon, alt_m]")
    home_lat, home_lon, home_alt_m = (_number(src, f"mission.plannedHomePosition[{i}]", v)
                                      for i, v in enumerate(home))
    items = mission.get("items")
    if not isinstance(items, list) or not items:
        raise _qgc_fail(src, "mission.items", "no items to convert")
    waypoints = [{"name": "HOME", "lat_deg": round(home_lat, 7), "lon_deg": round(home_lon, 7)}]
    legs: list[dict] = [{"type": "IF", "fix": "HOME"}]
    runways, notes, cruise_ft = [], [], None
    prev = (home_lat, home_lon)
    for i, item in enumerate(items):
        where = f"mission.items[{i}]"
        if not isinstance(item, dict) or item.get("type") != "SimpleItem":
            kind = item.get("complexItemType", item.get("type")) if isinstance(item, dict) \
                else type(item).__name__
            raise _qgc_fail(src, where, f"a {kind} item cannot be converted: only simple items "
                            f"({', '.join(_QGC_COMMANDS.values())})")
        cmd = item.get("command")
        if cmd not in _QGC_COMMANDS:
            known = ", ".join(f"{k} {v}" for k, v in _QGC_COMMANDS.items())
            raise _qgc_fail(src, f"{where}.command", f"MAVLink command {cmd!r} cannot be "
                            f"converted (only {known})")
        params = item.get("params")
        if not isinstance(params, list) or len(params) != 7:
            raise _qgc_fail(src, f"{where}.params", "not a list of 7 parameters")
        if legs[-1]["type"] == "AUTOLAND":
            raise _qgc_fail(src, where, "follows the landing, which ends the mission")
        alt_ft = round(_altitude_m(src, where, item, home_alt_m) / geometry.FT)
        cruise_ft = alt_ft if cruise_ft is None else cruise_ft
        lat, lon = (_number(src, f"{where}.params[{k}]", params[k]) if params[k] is not None
                    else 0.0 for k in (4, 5))
        if cmd == 22:
            if i:
                raise _qgc_fail(src, where, "a takeoff after the start cannot be flown (the "
                                "aircraft starts in the air)")
            if lat or lon:
                waypoints[0].update(lat_deg=round(lat, 7), lon_deg=round(lon, 7))
                prev = (lat, lon)
            legs[0]["altitude_ft"] = alt_ft
            continue
        if cmd == 21:
            frame = geometry.Frame(home_lat, home_lon)
            a, b = frame.to_local(*prev), frame.to_local(lat, lon)
            heading = geometry.bearing_deg(a, b)
            # QGroundControl's land point is where it touches down: the runway's aim point
            thr = b - RUNWAY_DEFAULTS["aim_point_m"] * geometry.unit(heading)
            t_lat, t_lon = frame.to_geo(*thr)
            name = f"RWY{round(heading / 10.0) % 36 or 36:02d}"
            runways.append({"name": name, "threshold": {"lat_deg": round(float(t_lat), 7),
                                                        "lon_deg": round(float(t_lon), 7)},
                            "elevation_ft": round(home_alt_m / geometry.FT),
                            "heading_deg": round(heading, 1), "length_m": 1500,
                            **RUNWAY_DEFAULTS})
            legs.append({"type": "AUTOLAND", "runway": name})
            continue
        name = f"WP{len(waypoints)}"
        waypoints.append({"name": name, "lat_deg": round(lat, 7), "lon_deg": round(lon, 7)})
        prev = (lat, lon)
        if cmd == 16:
            legs.append({"type": "TF", "fix": name, "altitude_ft": alt_ft})
            continue
        tas = geometry.tas_kt(airspeed_kt, alt_ft)
        r_min = 50.0 * math.ceil(geometry.turn_radius_m(tas, LIMIT_DEFAULTS["max_bank_deg"])
                                 / 50.0)
        p3 = _number(src, f"{where}.params[2]", params[2] or 0.0)
        if abs(p3) < r_min:
            notes.append(f"{where}: loiter radius {abs(p3):g} m raised to {r_min:g} m (the "
                         f"turn radius at {airspeed_kt:g} kt and a "
                         f"{LIMIT_DEFAULTS['max_bank_deg']:g}° bank)")
        leg = {"type": "ORBIT", "fix": name, "radius_m": max(abs(p3), r_min),
               "turn": "left" if p3 < 0 else "right"}
        if cmd == 17:
            leg["laps"] = 0
        elif cmd == 18:
            leg["laps"] = max(1, round(_number(src, f"{where}.params[0]", params[0])))
        else:
            leg["time_s"] = _number(src, f"{where}.params[0]", params[0])
        legs.append({**leg, "altitude_ft": alt_ft})
    stem = re.sub(r"[^A-Za-z0-9_-]", "_", Path(src).stem)
    name = (stem if stem[:1].isalpha() else f"m{stem}")[:16]
    out = {"mission": name, "description": f"converted from {Path(src).name}",
           "plan_id": plan_id, "origin": {"lat_deg": round(home_lat, 7),
                                          "lon_deg": round(home_lon, 7)},
           "cruise": {"airspeed_kt": airspeed_kt, "altitude_ft": cruise_ft},
           "limits": dict(LIMIT_DEFAULTS), "waypoints": waypoints}
    if runways:
        out["runways"] = runways
    out["legs"] = legs
    return out, notes


def _flow(value) -> str:
    import yaml

    if not isinstance(value, dict | list):
        return json.dumps(value)  # a JSON scalar is a YAML scalar
    return yaml.safe_dump(value, default_flow_style=True, sort_keys=False, width=10_000).strip()


def plan_yaml(doc: dict, header: str) -> str:
    """A mission plan document as YAML, a line per waypoint, runway and leg."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    for key, value in doc.items():
        if isinstance(value, list):
            lines.append(f"{key}:")
            lines += [f"  - {_flow(v)}" for v in value]
        else:
            lines.append(f"{key}: {_flow(value)}")
    return "\n".join(lines) + "\n"


def _import(args: argparse.Namespace) -> int:
    from ima.mission import plan

    src = str(args.file)
    try:
        with open(args.file, "rb") as f:
            data = f.read(MAX_QGC_BYTES + 1)
    except OSError as exc:
        raise ImaError(f"{src}: cannot read: {exc.strerror}", exit_code=2) from exc
    if len(data) > MAX_QGC_BYTES:
        raise ImaError(f"{src}: refused: larger than {MAX_QGC_BYTES:,} bytes", exit_code=2)
    try:
        doc = json.loads(data)
    except (ValueError, RecursionError) as exc:
        raise ImaError(f"{src}: not a JSON file: {exc}", exit_code=2) from exc
    out = args.output or Path(args.file.stem + ".yaml")
    if out.exists() and not args.force:
        raise ImaError(f"{out}: exists already (--force writes over it)", exit_code=2)
    mission, notes = convert_qgc(doc, src, args.airspeed, zlib.crc32(data) & 0xFFFFFFFF)
    plan.parse(mission, str(out))  # what is written passes `ima mission check`
    text = plan_yaml(mission, f"Converted from the QGroundControl plan {args.file.name} by "
                     "`ima mission import` (docs/mission.md).")
    try:
        out.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ImaError(f"{out}: cannot write: {exc.strerror}") from exc
    for note in notes:
        print(f"note: {note}", file=sys.stderr)
    print(out)
    return 0


def run(args: argparse.Namespace) -> int:
    return {"check": _check, "show": _show, "import": _import}[args.action](args)
