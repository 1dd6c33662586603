# SPDX-License-Identifier: Apache-2.0
"""The planned path of a mission plan in its local frame (metres north and east of the
origin, flat earth on a sphere of radius R_EARTH_M): one LegPath per leg, with the points it
flies, its length, its altitudes along it, and the vertical profile of the whole mission. What
`ima mission show` draws, and what a flown track is judged against (docs/mission.md, "The
planned path"). Building it also refuses what the aircraft cannot fly: a turn tighter than
its bank limit allows, an arc whose ends are not on one circle, a climb steeper than
limits.max_vs_fpm, a final above the glide path."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ima.mission.plan import ENDS_AT_FIX, Leg, MissionPlanError, Plan

R_EARTH_M = 6371008.8  # mean Earth radius (IUGG)
G = 9.80665
FT = 0.3048  # metres per foot
KT = 1852.0 / 3600.0  # metres per second per knot
STANDARD_RATE_DEG_S = 3.0  # holds turn at this rate, or at max_bank_deg if that is less
OPEN_LEG_M = 3000.0  # CA, FA, VA: at least this long
CF_MIN_M = 2000.0  # a CF's course line: at least this long
ARC_STEP_DEG = 2.0  # arcs are drawn with a point every this many degrees
ALT_SLACK = 1.1  # a climb may be this much steeper than max_vs_fpm before it is refused
GLIDE_SLACK_FT = 150.0  # how far above the glide path a final may begin
RADIUS_SLACK = 0.99  # an arc may be this much tighter than the bank limit allows


class Frame:
    """The plan's local frame: north and east metres from the origin."""

    def __init__(self, lat0_deg: float, lon0_deg: float) -> None:
        self.lat0_deg = lat0_deg
        self.lon0_deg = lon0_deg
        self.m_per_deg_n = math.radians(1.0) * R_EARTH_M
        self.m_per_deg_e = self.m_per_deg_n * math.cos(math.radians(lat0_deg))

    def to_local(self, lat_deg, lon_deg) -> np.ndarray:
        """(..., 2) north, east in metres of latitudes and longitudes (scalars or arrays)."""
        lat = np.asarray(lat_deg, dtype=float)
        dlon = (np.asarray(lon_deg, dtype=float) - self.lon0_deg + 180.0) % 360.0 - 180.0
        return np.stack([(lat - self.lat0_deg) * self.m_per_deg_n, dlon * self.m_per_deg_e],
                        axis=-1)

    def to_geo(self, north_m, east_m) -> tuple[np.ndarray, np.ndarray]:
        """Latitude and longitude (degrees) of local positions."""
        lat = self.lat0_deg + np.asarray(north_m, dtype=float) / self.m_per_deg_n
        lon = self.lon0_deg + np.asarray(east_m, dtype=float) / self.m_per_deg_e
        return lat, (lon + 180.0) % 360.0 - 180.0


def tas_kt(ias_kt: float, alt_ft: float) -> float:
    """True airspeed of an indicated airspeed at an altitude (ISA, no compressibility)."""
    sigma = (1.0 - 2.25577e-5 * alt_ft * FT) ** 4.25588
    return ias_kt / math.sqrt(sigma)


def turn_radius_m(tas_kt_: float, bank_deg: float) -> float:
    """r = V^2 / (g tan(bank)), no wind."""
    v = tas_kt_ * KT
    return v * v / (G * math.tan(math.radians(bank_deg)))


def hold_bank_deg(tas_kt_: float, max_bank_deg: float) -> float:
    """The bank of a standard-rate turn (3 deg/s), or max_bank_deg if that is less."""
    rate = math.radians(STANDARD_RATE_DEG_S)
    return min(max_bank_deg, math.degrees(math.atan(tas_kt_ * KT * rate / G)))


def bearing_deg(a, b) -> float:
    """The course (degrees, 0..360) from a to b."""
    return math.degrees(math.atan2(b[1] - a[1], b[0] - a[0])) % 360.0


def _u(rad: float) -> np.ndarray:
    return np.array([math.cos(rad), math.sin(rad)])


def unit(course_deg: float) -> np.ndarray:
    """The unit vector (north, east) along a course."""
    return _u(math.radians(course_deg))


def _mod2pi(a: float) -> float:
    a %= 2.0 * math.pi
    return 0.0 if a > 2.0 * math.pi - 1e-9 else a


class _Trace:
    """Flies straights and constant-radius turns from a pose, with a point every few degrees;
    its length is exact, not the polyline's."""

    def __init__(self, p, course_deg: float) -> None:
        self.p = np.asarray(p, dtype=float)
        self.crs = math.radians(course_deg)
        self.pts = [self.p]
        self.length = 0.0

    def straight(self, d: float) -> None:
        if d > 0.0:
            self.p = self.p + d * _u(self.crs)
            self.pts.append(self.p)
            self.length += d

    def turn(self, side: int, angle: float, r: float) -> None:
        """Turns `angle` radians, to the right (side +1) or left (-1), on radius r."""
        if angle <= 0.0:
            return
        c = self.p + r * _u(self.crs + side * math.pi / 2.0)
        b0 = self.crs - side * math.pi / 2.0
        k = max(1, math.ceil(math.degrees(angle) / ARC_STEP_DEG))
        self.pts += [c + r * _u(b0 + side * angle * i / k) for i in range(1, k + 1)]
        self.p = self.pts[-1]
        self.crs += side * angle
        self.length += r * angle

    def follow(self, path: Dubins) -> None:
        for kind, length in zip(path.word, path.segments, strict=True):
            if kind == "S":
                self.straight(length)
            else:
                self.turn(1 if kind == "R" else -1, length / path.radius_m, path.radius_m)

    @property
    def course_deg(self) -> float:
        return math.degrees(self.crs) % 360.0

    def points(self) -> np.ndarray:
        return np.array(self.pts)


@dataclass(frozen=True)
class Dubins:
    """A Dubins path: `word` names its segments in order (L, R: turns of radius_m to the left
    or right; S: a straight), `segments` their lengths in metres."""

    word: str
    segments: tuple[float, float, float]
    radius_m: float

    @property
    def length_m(self) -> float:
        return sum(self.segments)


def _advance(p: np.ndarray, crs: float, kind: str, length: float, r: float):
    if kind == "S":
        return p + length * _u(crs), crs
    side = 1 if kind == "R" else -1
    c = p + r * _u(crs + side * math.pi / 2.0)
    return c + r * _u(crs - side * math.pi / 2.0 + side * length / r), crs + side * length / r


def dubins(start, start_course_deg: float, end, end_course_deg: float,
           radius_m: float) -> Dubins:
    """The shortest path of bounded curvature from pose (start, course) to pose (end, course):
    the shortest of LSL, RSR, LSR, RSL, RLR and LRL that exist (Dubins 1957)."""
    p0, p1 = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    a0, a1, r = math.radians(start_course_deg), math.radians(end_course_deg), radius_m

    def centre(p, a, side):
        return p + r * _u(a + side * math.pi / 2.0)

    found: list[tuple[str, tuple[float, float, float]]] = []
    for word, s1, s2 in (("LSL", -1, -1), ("RSR", 1, 1), ("LSR", -1, 1), ("RSL", 1, -1)):
        v = centre(p1, a1, s2) - centre(p0, a0, s1)
        d, phi = math.hypot(*v), math.atan2(v[1], v[0])
        if s1 == s2:
            psi, straight = (phi, d) if d > 1e-9 * r else (a0, 0.0)  # one circle: one arc
        elif d >= 2.0 * r:
            psi, straight = phi + s1 * math.asin(2.0 * r / d), math.sqrt(d * d - 4.0 * r * r)
        else:
            continue
        found.append((word, (r * _mod2pi(s1 * (psi - a0)), straight,
                             r * _mod2pi(s2 * (a1 - psi)))))
    for word, s in (("RLR", 1), ("LRL", -1)):
        c1, c3 = centre(p0, a0, s), centre(p1, a1, s)
        v = c3 - c1
        d = math.hypot(*v)
        if d > 4.0 * r or d < 1e-9:
            continue
        h = math.sqrt(4.0 * r * r - d * d / 4.0)
        for other in (1, -1):
            c2 = c1 + v / 2.0 + other * h * _u(math.atan2(v[1], v[0]) + math.pi / 2.0)
            psi_a = math.atan2(*(c2 - c1)[::-1]) + s * math.pi / 2.0
            psi_b = math.atan2(*(c3 - c2)[::-1]) - s * math.pi / 2.0
            found.append((word, (r * _mod2pi(s * (psi_a - a0)), r * _mod2pi(s * (psi_a - psi_b)),
                                 r * _mod2pi(s * (a1 - psi_b)))))
    best: Dubins | None = None
    for word, segs in found:
        p, a = p0, a0
        for kind, length in zip(word, segs, strict=True):
            p, a = _advance(p, a, kind, length, r)
        arrives = math.hypot(*(p - p1)) <= 1e-6 * (r + math.hypot(*(p1 - p0))) + 1e-6 and \
            abs(math.remainder(a - a1, 2.0 * math.pi)) <= 1e-6
        # of equal lengths, the first found (a plain arc is named RSR, not LSR with no L)
        if arrives and (best is None or sum(segs) < best.length_m * (1.0 - 1e-12) - 1e-9):
            best = Dubins(word, segs, r)
    assert best is not None, "LSL and RSR always exist"
    return best


@dataclass(eq=False)
class LegPath:
    """One leg's planned path. `points` (N x 2: north, east in metres, in flying order) is the
    leg proper; `entry` the straight from where the previous leg ends to its start, for the
    legs that begin somewhere of their own (FA, holds, ORBIT, SCAN, AUTOLAND); `profile` the
    planned altitude (ft) against the distance flown from the start of the entry (m)."""

    index: int  # in the image: the mission's legs, then the procedures'
    type: str
    label: str  # "3 HM"
    kind: str  # point, line, arc, racetrack, scan, dubins, final
    points: np.ndarray
    entry: np.ndarray
    length_m: float
    entry_m: float
    start_alt_ft: float
    altitude_ft: float  # at the leg's end
    airspeed_kt: float  # indicated
    tas_kt: float
    profile: np.ndarray  # K x 2: distance (m), altitude (ft)
    procedure: str | None = None  # the contingency whose procedure it is; None: the mission
    fix: str | None = None
    end_course_deg: float | None = None
    radius_m: float | None = None  # RF, ORBIT, holds, DUBINS; SCAN: its turns
    center: np.ndarray | None = None  # RF, ORBIT
    laps: int | None = None  # holds and ORBIT: the circuits drawn
    passes: tuple[np.ndarray, ...] = field(default_factory=tuple)  # SCAN: each pass's ends
    word: str | None = None  # DUBINS: e.g. "RSL"

    @property
    def total_m(self) -> float:
        return self.entry_m + self.length_m

    @property
    def duration_s(self) -> float:
        return self.total_m / (self.tas_kt * KT)

    def altitude_at(self, distance_m):
        """The planned altitude (ft) at a distance flown from the start of the entry."""
        return np.interp(distance_m, self.profile[:, 0], self.profile[:, 1])

    def distance_to(self, ne) -> np.ndarray:
        """How far (m) each of the positions ne (M x 2: north, east) is from the leg proper."""
        q = np.atleast_2d(np.asarray(ne, dtype=float))
        if len(self.points) == 0:
            return np.full(len(q), np.inf)
        if len(self.points) == 1:
            return np.hypot(*(q - self.points[0]).T)
        a, b = self.points[:-1], self.points[1:]
        ab = b - a
        den = np.maximum((ab * ab).sum(axis=1), 1e-12)
        t = np.clip(((q[:, None, :] - a) * ab).sum(axis=2) / den, 0.0, 1.0)
        near = a + t[..., None] * ab
        return np.hypot(*(q[:, None, :] - near).transpose(2, 0, 1)).min(axis=1)


@dataclass(eq=False)
class Profile:
    """The mission's planned altitude against the distance flown along its path."""

    distance_m: np.ndarray
    altitude_ft: np.ndarray
    leg_start_m: dict[int, float]  # leg index -> where its entry (or the leg) begins


@dataclass
class _State:
    """Where the previous leg left the aircraft (pos None: not known, a procedure's start)."""

    pos: np.ndarray | None
    course: float | None
    alt: float
    fix: str | None = None  # the fix it ended over
    prev: Leg | None = None


_NO_POINTS = np.zeros((0, 2))


class _Builder:
    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self.frame = Frame(plan.origin_lat_deg, plan.origin_lon_deg)
        self.pos = {n: self.frame.to_local(w.lat_deg, w.lon_deg)
                    for n, w in plan.waypoints.items()}
        self.lim = plan.limits

    def fail(self, where: str, message: str) -> MissionPlanError:
        return MissionPlanError(f"{self.plan.path}: {where}: {message}")

    def min_radius(self, r: float, tas: float, ias: float, what: str) -> None:
        r_min = turn_radius_m(tas, self.lim.max_bank_deg)
        if r < r_min * RADIUS_SLACK:
            raise self.fail(what, f"{r:.0f} m is a tighter turn than the aircraft flies at "
                            f"{ias:g} kt ({tas:.0f} kt true) within limits.max_bank_deg "
                            f"{self.lim.max_bank_deg:g} ({r_min:.0f} m at least)")

    def leg(self, index: int, leg: Leg, procedure: str | None, st: _State):
        """The leg's path and the state it leaves."""
        ias = leg.airspeed_kt if leg.airspeed_kt is not None else self.plan.cruise_airspeed_kt
        if leg.type == "IF":
            h0 = leg.altitude_ft if leg.altitude_ft is not None else st.alt
        else:
            h0 = st.alt
        if leg.type == "AUTOLAND":
            h1 = self.plan.runways[leg.runway].elevation_ft
        else:
            h1 = leg.altitude_ft if leg.altitude_ft is not None else h0
        tas = tas_kt(ias, (h0 + h1) / 2.0)
        grad = self.lim.max_vs_fpm / (tas * KT * 60.0)  # ft per m at the climb limit
        climb_m = abs(h1 - h0) / grad
        fix = self.pos.get(leg.fix) if leg.fix else None
        out = dict(kind="line", points=_NO_POINTS, entry=_NO_POINTS, length=0.0, end=fix,
                   course=None, profile=None)
        getattr(self, f"_{leg.type.lower()}")(leg, st, fix, out, tas=tas, ias=ias,
                                                h0=h0, h1=h1, climb_m=climb_m)
        entry_m = float(np.hypot(*np.diff(out["entry"], axis=0).T).sum())
        total = entry_m + out["length"]
        sized = leg.type in ("IF", "CA", "FA", "VA", "HA", "AUTOLAND")
        if not sized and abs(h1 - h0) > 0.0 and st.pos is not None and \
                climb_m > ALT_SLACK * total + 1.0:
            raise self.fail(f"{leg.where}.altitude_ft", f"{'climb' if h1 > h0 else 'descent'} "
                            f"of {abs(h1 - h0):g} ft needs {climb_m / 1000:.1f} km at "
                            f"{self.lim.max_vs_fpm:g} ft/min and {tas:.0f} kt true; the leg is "
                            f"{total / 1000:.1f} km")
        profile = out["profile"]
        if profile is None:
            if h1 == h0 or leg.geometric or climb_m >= total:
                profile = [(0.0, h0), (total, h1)]
            else:
                profile = [(0.0, h0), (climb_m, h1), (total, h1)]
        path = LegPath(index=index, type=leg.type, label=f"{index} {leg.type}", kind=out["kind"],
                       points=np.asarray(out["points"], dtype=float).reshape(-1, 2),
                       entry=out["entry"], length_m=float(out["length"]), entry_m=entry_m,
                       start_alt_ft=h0, altitude_ft=h1, airspeed_kt=ias, tas_kt=tas,
                       profile=np.asarray(profile, dtype=float), procedure=procedure,
                       fix=leg.fix or leg.runway, end_course_deg=out["course"],
                       radius_m=out.get("radius"), center=out.get("center"),
                       laps=out.get("laps"), passes=tuple(out.get("passes", ())),
                       word=out.get("word"))
        end = out["end"]
        return path, _State(pos=None if end is None else np.asarray(end, dtype=float),
                            course=out["course"], alt=h1,
                            fix=leg.fix if leg.type in ENDS_AT_FIX else None, prev=leg)

    @staticmethod
    def _entry(st: _State, to) -> np.ndarray:
        if st.pos is None or math.hypot(*(to - st.pos)) < 1.0:
            return _NO_POINTS
        return np.array([st.pos, to])

    # -- the legs ------------------------------------------------------------------------------

    def _if(self, leg, st, fix, out, **_):
        out.update(kind="point", points=[fix])

    def _tf(self, leg, st, fix, out, **_):
        if st.pos is None:
            out["points"] = [fix]
            return
        if math.hypot(*(fix - st.pos)) < 1.0:
            raise self.fail(f"{leg.where}.fix", f"'{leg.fix}' is where the previous leg ends "
                            f"(a {leg.type} of no length)")
        out.update(points=[st.pos, fix], length=math.hypot(*(fix - st.pos)),
                   course=bearing_deg(st.pos, fix))

    _df = _direct = _tf

    def _cf(self, leg, st, fix, out, **_):
        back = CF_MIN_M if st.pos is None else max(math.hypot(*(fix - st.pos)), CF_MIN_M)
        out.update(points=[fix - back * unit(leg.course_deg), fix], length=back,
                   course=leg.course_deg)

    def _rf(self, leg, st, fix, out, tas, ias, **_):
        if st.fix is None:
            raise self.fail(leg.where, "an RF arc starts over the fix the previous leg ends "
                            f"over, and {st.prev.where} ({st.prev.type}) ends over none")
        c = self.pos[leg.center]
        r, r0 = math.hypot(*(fix - c)), math.hypot(*(st.pos - c))
        if abs(r - r0) > max(0.02 * r, 10.0):
            raise self.fail(f"{leg.where}.center", f"'{leg.center}' is {r0:.0f} m from the "
                            f"arc's start ({st.fix}) and {r:.0f} m from its end ({leg.fix}): an "
                            "RF arc keeps one radius")
        self.min_radius(r, tas, ias, f"{leg.where}.center")
        side = 1 if leg.turn == "right" else -1
        b0, b1 = bearing_deg(c, st.pos), bearing_deg(c, fix)
        sweep = (side * (b1 - b0)) % 360.0
        if sweep < 0.5:
            raise self.fail(f"{leg.where}.fix", "the arc ends where it starts")
        k = max(1, math.ceil(sweep / ARC_STEP_DEG))
        pts = [c + r * unit(b0 + side * sweep * i / k) for i in range(k + 1)]
        out.update(kind="arc", points=pts, length=r * math.radians(sweep),
                   course=(b1 + side * 90.0) % 360.0, radius=r, center=c)

    def _open_length(self, climb_m: float) -> float:
        return max(OPEN_LEG_M, climb_m)

    def _ca(self, leg, st, fix, out, climb_m, **_):
        length = self._open_length(climb_m)
        out.update(length=length, course=leg.course_deg)
        if st.pos is not None:
            end = st.pos + length * unit(leg.course_deg)
            out.update(points=[st.pos, end], end=end)

    _va = _ca

    def _fa(self, leg, st, fix, out, climb_m, **_):
        length = self._open_length(climb_m)
        end = fix + length * unit(leg.course_deg)
        out.update(points=[fix, end], entry=self._entry(st, fix), length=length, end=end,
                   course=leg.course_deg)

    def _hold(self, leg, st, fix, out, tas, h0, h1, climb_m, **_):
        r = turn_radius_m(tas, hold_bank_deg(tas, self.lim.max_bank_deg))
        straight = leg.leg_time_s * tas * KT
        circuit = 2.0 * math.pi * r + 2.0 * straight
        if leg.type == "HA":
            laps = max(1, math.ceil(climb_m / circuit - 1e-9))
        else:
            laps = leg.laps or 1
        side = 1 if leg.turn == "right" else -1
        t = _Trace(fix, leg.course_deg)
        for _lap in range(laps):
            t.turn(side, math.pi, r)
            t.straight(straight)
            t.turn(side, math.pi, r)
            t.straight(straight)
        out.update(kind="racetrack", points=t.points(), entry=self._entry(st, fix),
                   length=t.length, course=leg.course_deg, radius=r, laps=laps)

    _ha = _hf = _hm = _hold

    def _orbit(self, leg, st, fix, out, tas, ias, **_):
        r = leg.radius_m
        self.min_radius(r, tas, ias, f"{leg.where}.radius_m")
        side = 1 if leg.turn == "right" else -1
        if st.pos is None:
            b0 = 0.0
        elif math.hypot(*(st.pos - fix)) < 1.0:
            b0 = st.course or 0.0
        else:
            b0 = bearing_deg(fix, st.pos)
        start = fix + r * unit(b0)
        if leg.time_s is not None:
            sweep = math.degrees(leg.time_s * tas * KT / r)
        else:
            sweep = 360.0 * (leg.laps or 1)
        k = max(1, math.ceil(sweep / ARC_STEP_DEG))
        pts = [fix + r * unit(b0 + side * sweep * i / k) for i in range(k + 1)]
        laps = None if leg.time_s is not None else (leg.laps or 1)
        # where the orbit ends on its circle depends on how it was joined: the next leg
        # starts from the orbit's fix (as the mission manager flies it)
        out.update(kind="arc", points=pts, entry=self._entry(st, start),
                   length=r * math.radians(sweep), end=fix,
                   course=(b0 + side * (sweep + 90.0)) % 360.0, radius=r, center=fix, laps=laps)

    def _scan(self, leg, st, fix, out, tas, **_):
        r = turn_radius_m(tas, self.lim.max_bank_deg)
        side = unit(leg.course_deg + (90.0 if leg.turn == "right" else -90.0))
        along = leg.length_m * unit(leg.course_deg)
        t = _Trace(fix, leg.course_deg)
        passes = []
        for k in range(leg.passes):
            a = fix + k * leg.spacing_m * side + (along if k % 2 else 0.0)
            crs = (leg.course_deg + (180.0 if k % 2 else 0.0)) % 360.0
            if k:
                t.follow(dubins(t.p, t.course_deg, a, crs, r))
            t.straight(leg.length_m)
            passes.append(np.array([a, t.p]))
        out.update(kind="scan", points=t.points(), entry=self._entry(st, fix), length=t.length,
                   end=t.p, course=t.course_deg, radius=r, passes=passes)

    def _dubins(self, leg, st, fix, out, tas, ias, **_):
        self.min_radius(leg.radius_m, tas, ias, f"{leg.where}.radius_m")
        out.update(kind="dubins", points=[fix], course=leg.course_deg)
        if st.pos is None:
            return
        course = st.course
        if course is None:
            course = bearing_deg(st.pos, fix) if math.hypot(*(fix - st.pos)) >= 1.0 else 0.0
        path = dubins(st.pos, course, fix, leg.course_deg, leg.radius_m)
        t = _Trace(st.pos, course)
        t.follow(path)
        out.update(points=t.points(), length=path.length_m, radius=leg.radius_m, word=path.word)

    def _autoland(self, leg, st, fix, out, h0, **_):
        rw = self.plan.runways[leg.runway]
        thr = self.frame.to_local(rw.lat_deg, rw.lon_deg)
        u = unit(rw.heading_deg)
        tan_gp = math.tan(math.radians(rw.glide_path_deg))

        def glide(s):  # the glide path's altitude (ft) s metres past the threshold
            return rw.elevation_ft + (rw.aim_point_m - s) * tan_gp / FT

        if h0 - rw.elevation_ft < 50.0:
            raise self.fail(leg.where, f"it begins at {h0:g} ft, not above the runway "
                            f"({rw.elevation_ft:g} ft)")
        s_start = rw.aim_point_m - (h0 - rw.elevation_ft) * FT / tan_gp  # the intercept
        if st.pos is not None:
            s_start = max(s_start, float((st.pos - thr) @ u))
        if s_start >= 0.0 or h0 - glide(s_start) > GLIDE_SLACK_FT:
            raise self.fail(leg.where, f"the final begins {-s_start / 1000:.1f} km before the "
                            f"threshold at {h0:g} ft, {h0 - glide(s_start):.0f} ft above the "
                            f"{rw.glide_path_deg:g}° glide path: descend earlier, or end the "
                            "leg before it farther out on the centre line")
        start = thr + s_start * u
        entry = self._entry(st, start)
        entry_m = float(np.hypot(*np.diff(entry, axis=0).T).sum())
        length = rw.length_m - s_start
        aim = entry_m + rw.aim_point_m - s_start
        out.update(kind="final", points=[start, thr, thr + rw.length_m * u], entry=entry,
                   length=length, end=thr + rw.length_m * u, course=rw.heading_deg,
                   profile=[(0.0, h0), (entry_m, glide(s_start)), (aim, rw.elevation_ft),
                            (entry_m + length, rw.elevation_ft)])


def leg_paths(plan: Plan) -> list[LegPath]:
    """Every leg's planned path, in the image's order: the mission's from its IF, then each
    procedure's from an unknown start (its first leg begins where it begins) at the cruise
    altitude. Raises MissionPlanError for a path the aircraft cannot fly."""
    b = _Builder(plan)
    out: list[LegPath] = []
    st = _State(pos=None, course=None, alt=plan.cruise_altitude_ft)
    for leg in plan.legs:
        path, st = b.leg(len(out), leg, None, st)
        out.append(path)
    for c in plan.contingencies.values():
        st = _State(pos=None, course=None, alt=plan.cruise_altitude_ft)
        for leg in c.procedure:
            path, st = b.leg(len(out), leg, c.name, st)
            out.append(path)
    return out


def vertical_profile(plan: Plan, paths: list[LegPath] | None = None) -> Profile:
    """The mission's planned altitude against the distance flown along its path."""
    paths = leg_paths(plan) if paths is None else paths
    dist, alt, starts = [], [], {}
    offset = 0.0
    for p in paths:
        if p.procedure is not None:
            continue
        starts[p.index] = offset
        dist += list(offset + p.profile[:, 0])
        alt += list(p.profile[:, 1])
        offset += p.total_m
    return Profile(np.array(dist), np.array(alt), starts)
