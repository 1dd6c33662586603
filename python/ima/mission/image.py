# SPDX-License-Identifier: Apache-2.0
"""The binary image of a mission plan, as partitions/include/rpas/mission_plan.h defines it
(that header is the authority; tests/mission checks this mirror against it with a C compiler):
one 200-byte header, then 48-byte legs, the mission's first and each contingency procedure's
after them; little-endian, a float that does not apply is NaN, positions in 1e-7 degrees."""

from __future__ import annotations

import math
import struct
import zlib

from ima.mission.plan import CONTINGENCIES, Leg, MissionPlanError, Plan

PLAN_MAGIC = 0x4E4C504D  # RPAS_PLAN_MAGIC: "MPLN" as little-endian bytes
PLAN_VERSION = 1  # RPAS_PLAN_VERSION
PLAN_MAX_LEGS = 48  # RPAS_PLAN_MAX_LEGS

# enum rpas_leg_type
LEG_TYPES = {"IF": 1, "TF": 2, "DF": 3, "CF": 4, "RF": 5, "CA": 6, "FA": 7, "VA": 8, "HA": 9,
             "HF": 10, "HM": 11, "DUBINS": 12, "SCAN": 13, "ORBIT": 14, "DIRECT": 15,
             "AUTOLAND": 16}
# rpas_plan_leg_t.flags: RPAS_LEG_<name>
LEG_FLAGS = {"FLY_OVER": 0x01, "TURN_RIGHT": 0x02, "TURN_LEFT": 0x04, "ALT_PATH": 0x08}
# enum rpas_contingency: RPAS_CT_<name>, in the order of plan.CONTINGENCIES
CONTINGENCY_CODES = {"C2_LOSS": 0, "GPS_LOSS": 1, "TRAFFIC": 2, "AP_DISENGAGE": 3,
                     "TERMINATION": 4}
CT_COUNT = 5  # RPAS_CT_COUNT
# enum rpas_ct_action: RPAS_CTA_<name>
ACTION_CODES = {"NONE": 0, "PROCEDURE": 1, "AVOID": 2, "HOLD": 3, "TERMINATE": 4}

# The records, field by field as the C structs declare them (an array as one field).
LEG_FIELDS = (("type", "B"), ("flags", "B"), ("count", "H"), ("lat_e7", "i"), ("lon_e7", "i"),
              ("lat2_e7", "i"), ("lon2_e7", "i"), ("course_deg", "f"), ("alt_ft", "f"),
              ("ias_kt", "f"), ("a", "f"), ("b", "f"), ("c", "f"), ("d", "f"))
CONTINGENCY_FIELDS = (("action", "B"), ("resume", "B"), ("first_leg", "H"), ("n_legs", "H"),
                      ("pad", "H"), ("detect_s", "f"), ("continue_s", "f"), ("p1", "f"),
                      ("p2", "f"))
HEADER_FIELDS = (("magic", "I"), ("version", "H"), ("n_legs", "H"), ("n_mission_legs", "H"),
                 ("flags", "H"), ("plan_id", "I"), ("origin_lat_e7", "i"),
                 ("origin_lon_e7", "i"), ("cruise_ias_kt", "f"), ("cruise_alt_ft", "f"),
                 ("min_ias_kt", "f"), ("max_ias_kt", "f"), ("max_bank_deg", "f"),
                 ("max_vs_fpm", "f"), ("traffic_h_m", "f"), ("traffic_v_ft", "f"),
                 ("pad", "6f"), ("contingency", f"{CT_COUNT * 24}s"))

LEG = struct.Struct("<" + "".join(f for _, f in LEG_FIELDS))
CONTINGENCY = struct.Struct("<" + "".join(f for _, f in CONTINGENCY_FIELDS))
HEADER = struct.Struct("<" + "".join(f for _, f in HEADER_FIELDS))
NAN = math.nan


def layout(fields) -> dict[str, tuple[int, int]]:
    """Each field's (offset, size) in bytes."""
    out, offset = {}, 0
    for name, fmt in fields:
        size = struct.calcsize("<" + fmt)
        out[name] = (offset, size)
        offset += size
    return out


def e7(deg: float) -> int:
    return round(deg * 1e7)


def _num(value: float | None) -> float:
    return NAN if value is None else float(value)


def _turn(leg: Leg) -> int:
    if leg.turn is None:
        return 0
    return LEG_FLAGS["TURN_RIGHT"] if leg.turn == "right" else LEG_FLAGS["TURN_LEFT"]


def _leg(plan: Plan, leg: Leg) -> bytes:
    flags = _turn(leg)
    if leg.fly_over:
        flags |= LEG_FLAGS["FLY_OVER"]
    if leg.geometric:
        flags |= LEG_FLAGS["ALT_PATH"]
    w = plan.waypoints.get(leg.fix) if leg.fix else None
    lat, lon = (e7(w.lat_deg), e7(w.lon_deg)) if w else (0, 0)
    lat2 = lon2 = count = 0
    course, alt, ias = _num(leg.course_deg), _num(leg.altitude_ft), _num(leg.airspeed_kt)
    a = b = c = d = NAN
    t = leg.type
    if t == "RF":
        centre = plan.waypoints[leg.center]
        lat2, lon2 = e7(centre.lat_deg), e7(centre.lon_deg)
    elif t in ("HA", "HF", "HM"):
        a = leg.leg_time_s
        count = leg.laps or 0
    elif t == "ORBIT":
        a, b = leg.radius_m, leg.time_s or 0.0
        count = leg.laps or 0
    elif t == "SCAN":
        a, b, count = leg.length_m, leg.spacing_m, leg.passes
    elif t == "DUBINS":
        a = leg.radius_m
    elif t == "AUTOLAND":
        rw = plan.runways[leg.runway]
        lat, lon = e7(rw.lat_deg), e7(rw.lon_deg)
        course, alt = rw.heading_deg, rw.elevation_ft
        a, b, c, d = rw.glide_path_deg, rw.aim_point_m, rw.length_m, rw.width_m
    return LEG.pack(LEG_TYPES[t], flags, count, lat, lon, lat2, lon2, course, alt, ias,
                    a, b, c, d)


def encode(plan: Plan) -> bytes:
    """The plan's image."""
    legs = plan.image_legs()
    if not 1 <= len(legs) <= PLAN_MAX_LEGS:
        raise MissionPlanError(f"{plan.path}: {len(legs)} legs; an image holds 1 to "
                               f"{PLAN_MAX_LEGS}")
    records = []
    first = len(plan.legs)
    for name in CONTINGENCIES:
        c = plan.contingencies.get(name)
        if c is None:
            records.append(CONTINGENCY.pack(ACTION_CODES["NONE"], 0, 0, 0, 0, 0.0, 0.0, NAN, NAN))
            continue
        n = len(c.procedure)
        p1, p2 = (c.offset_deg, c.altitude_offset_ft) if c.action == "avoid" else (NAN, NAN)
        records.append(CONTINGENCY.pack(ACTION_CODES[c.action.upper()], int(c.resume),
                                        first if n else 0, n, 0, c.detect_s,
                                        c.continue_s or 0.0, p1, p2))
        first += n
    lim = plan.limits
    header = HEADER.pack(PLAN_MAGIC, PLAN_VERSION, len(legs), len(plan.legs), 0, plan.plan_id,
                         e7(plan.origin_lat_deg), e7(plan.origin_lon_deg),
                         plan.cruise_airspeed_kt, plan.cruise_altitude_ft, lim.min_airspeed_kt,
                         lim.max_airspeed_kt, lim.max_bank_deg, lim.max_vs_fpm,
                         plan.traffic_h_m, plan.traffic_v_ft, *([NAN] * 6), b"".join(records))
    return header + b"".join(_leg(plan, leg) for leg, _ in legs)


def crc32(image: bytes) -> int:
    """The uplink's check of an image (rpas_crc32: IEEE 802.3, as zlib's)."""
    return zlib.crc32(image) & 0xFFFFFFFF


_LEG_NAMES = {v: k for k, v in LEG_TYPES.items()}
_CT_NAMES = dict(zip(CONTINGENCY_CODES.values(), CONTINGENCIES, strict=True))
_ACTION_NAMES = {v: k.lower() for k, v in ACTION_CODES.items()}


def decode(image: bytes) -> dict:
    """An image as a dict of the C structs' fields (contingency: a list of CT_COUNT dicts,
    legs: a list of dicts), plus `type_name`, `action_name` and `name` for reading;
    ValueError if it is not a whole image of this version."""
    if len(image) < HEADER.size:
        raise ValueError(f"{len(image)} bytes: shorter than the {HEADER.size}-byte header")
    values = HEADER.unpack_from(image)
    names = [n for n, _ in HEADER_FIELDS]
    h = dict(zip(names[:-2], values[:-7], strict=True))
    h["pad"] = list(values[-7:-1])
    if h["magic"] != PLAN_MAGIC:
        raise ValueError(f"magic 0x{h['magic']:08x}, not 0x{PLAN_MAGIC:08x}")
    if h["version"] != PLAN_VERSION:
        raise ValueError(f"version {h['version']}, not {PLAN_VERSION}")
    if len(image) != HEADER.size + h["n_legs"] * LEG.size:
        raise ValueError(f"{len(image)} bytes for {h['n_legs']} legs (expected "
                         f"{HEADER.size + h['n_legs'] * LEG.size})")
    h["contingency"] = []
    for k, rec in enumerate(CONTINGENCY.iter_unpack(values[-1])):
        c = dict(zip((n for n, _ in CONTINGENCY_FIELDS), rec, strict=True))
        c["name"], c["action_name"] = _CT_NAMES[k], _ACTION_NAMES.get(c["action"], "?")
        h["contingency"].append(c)
    h["legs"] = []
    for rec in LEG.iter_unpack(image[HEADER.size:]):
        leg = dict(zip((n for n, _ in LEG_FIELDS), rec, strict=True))
        leg["type_name"] = _LEG_NAMES.get(leg["type"], "?")
        h["legs"].append(leg)
    return h
