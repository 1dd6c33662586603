# SPDX-License-Identifier: Apache-2.0
"""The remote pilot model: how the pilot at the station flies DIRECT from the downlink alone.

When the flight control reports DIRECT on the downlink while the script does not fly the stick
itself, the model takes the stick. It sees only what the station shows: each FCS channel's
FCS_STATUS (mode, fallback, navigation flags, targets), NAV_POS (position) and NAV_DATA
(altitude, wind estimate, ground speed), from the channel the station shows. Nothing of the
truth. No attitude is downlinked, so the pilot reads, like a pilot flying by the map:

- the ground velocity: the least-squares slope of the positions over the last `window_s`;
- the heading: the direction of the air velocity, ground velocity minus the downlinked wind;
- the turn rate, hence the bank: the slope of that heading over the window;
- the vertical speed: the least-squares slope of the altitude over the window.

It holds the wings level and the last commanded heading and altitude with a heading -> turn
rate -> roll stick loop and an altitude -> vertical speed -> pitch stick loop, each with a
slow trim term, leaves the rudder neutral and the throttle where the station has it. Its inputs
come `reaction_s` after the telemetry they answer, and it takes the stick `takeover_s` after
the downlink first shows DIRECT. Deterministic: the same frames give the same stick.
"""

from __future__ import annotations

import math
from collections import deque

from .config import NS, PilotModelParams

DEG = 180.0 / math.pi
KT_MPS = 0.514444
R_EARTH_M = 6_378_137.0
# FCS_STATUS's FCS_MODE (config/can/rpas.dbc): DIRECT, and the modes that fly targets
_DIRECT = 1
_TARGET_MODES = (2, 3, 4)  # AUTOPILOT, MISSION, CONTINGENCY
_POS_VALID = 0x1 | 0x8  # FCS_NAV_FLAGS: GPS or dead reckoning: the position is current
_ALT_VALID = 0x1 | 0x4  # GPS or air data: the altitude is current


def _wrap180(x: float) -> float:
    return (x + 180.0) % 360.0 - 180.0


def _clamp(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else hi if x > hi else x


def _slope(pts) -> float | None:
    """Least-squares slope of [(t_s, value)] (per second); None with fewer than 4 points."""
    n = len(pts)
    if n < 4:
        return None
    mt = sum(t for t, _ in pts) / n
    mv = sum(v for _, v in pts) / n
    den = sum((t - mt) ** 2 for t, _ in pts)
    if den <= 0.0:
        return None
    return sum((t - mt) * (v - mv) for t, v in pts) / den


def _median(xs: list[float]) -> float:
    xs = sorted(xs)
    n = len(xs)
    return xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])


def _track_velocity(pts) -> tuple[float, float]:
    """Ground velocity (m/s north, east) from successive positions [(t_ns, n, e)]: the median of
    the velocities between neighbours. The map symbol moves smoothly between GPS fixes and
    jumps by the fix's error at each one; the median keeps the smooth motion, as the eye does."""
    vn, ve = [], []
    for (t0, n0, e0), (t1, n1, e1) in zip(pts, pts[1:]):
        if t1 > t0:
            dt = (t1 - t0) / NS
            vn.append((n1 - n0) / dt)
            ve.append((e1 - e0) / dt)
    return _median(vn), _median(ve)


class Telemetry:
    """One FCS channel's downlink as the station keeps it: the last status and a short history
    of positions (metres north and east of a reference) and altitudes."""

    def __init__(self, keep_ns: int) -> None:
        self.keep_ns = keep_ns
        self.status_t = -1
        self.mode = self.fallback = self.nav_flags = 0
        self.tgt_hdg = self.tgt_alt = 0.0
        self.ref: tuple[float, float] | None = None
        self.pos: deque = deque()  # (t_ns, north_m, east_m)
        self.alt: deque = deque()  # (t_ns, alt_ft)
        self.wind_to = (0.0, 0.0)  # north, east kt: where the air moves to
        self.data_t = -1

    def _trim(self, q: deque, t: int) -> None:
        while q and q[0][0] < t - self.keep_ns:
            q.popleft()

    def position(self, t: int, lat: float, lon: float) -> None:
        if not self.nav_flags & _POS_VALID:
            return  # the display shows no position it does not have (held or not yet known)
        if self.ref is None or abs(lat - self.ref[0]) > 0.5 or abs(lon - self.ref[1]) > 0.5:
            self.ref = (lat, lon)  # a new local frame (also far from the old one)
            self.pos.clear()
        n = (lat - self.ref[0]) / DEG * R_EARTH_M
        e = _wrap180(lon - self.ref[1]) / DEG * R_EARTH_M * math.cos(self.ref[0] / DEG)
        self.pos.append((t, n, e))
        self._trim(self.pos, t)

    def data(self, t: int, alt: float, wind_from_deg: float, wind_kt: float) -> None:
        if self.nav_flags & _ALT_VALID:
            self.alt.append((t, alt))
            self._trim(self.alt, t)
        a = wind_from_deg / DEG
        self.wind_to = (-wind_kt * math.cos(a), -wind_kt * math.sin(a))
        self.data_t = t


class PilotModel:
    """The pilot's eye and hands. The world feeds it the downlink (`status`, `nav_pos`,
    `nav_data`) and asks `stick()` at each PILOT_STICK; `events` collects what it did."""

    def __init__(self, p: PilotModelParams, enabled: bool = True) -> None:
        self.p = p
        self.enabled = enabled
        self.ch: dict[int, Telemetry] = {}
        self.keep_ns = round(max(p.window_s, p.vs_window_s) * NS)
        self.window_ns = round(p.window_s * NS)
        self.vs_window_ns = round(p.vs_window_s * NS)
        self.fresh_ns = round(p.fresh_s * NS)
        self.flying = False
        self.direct_since: int | None = None  # when the downlink first showed DIRECT
        self.targets: tuple[float, float] | None = None  # heading, altitude held
        self._script_targets: tuple[float, float] | None = None  # the script's, last seen
        self.last_auto_targets: tuple[float, float] | None = None  # the FCS's, not in DIRECT
        self.hdg_track: deque = deque()  # (t_ns, unwrapped heading estimate)
        self.roll_trim = self.pitch_trim = 0.0
        self.pending: deque = deque()  # (t due, (pitch, roll, power)): inputs on their way
        self.out = (0.0, 0.0, 0.0)
        self.last_t: int | None = None
        self.events: list[tuple[int, dict]] = []

    # -- the downlink ----------------------------------------------------------------------
    def _tm(self, ch: int) -> Telemetry:
        tm = self.ch.get(ch)
        if tm is None:
            tm = self.ch[ch] = Telemetry(self.keep_ns)
        return tm

    def status(self, ch: int, t: int, mode: int, fallback: int, nav_flags: int, tgt_hdg: float,
               tgt_alt: float) -> None:
        tm = self._tm(ch)
        tm.status_t, tm.mode, tm.fallback, tm.nav_flags = t, mode, fallback, nav_flags
        tm.tgt_hdg, tm.tgt_alt = tgt_hdg, tgt_alt

    def nav_pos(self, ch: int, t: int, lat: float, lon: float) -> None:
        self._tm(ch).position(t, lat, lon)

    def nav_data(self, ch: int, t: int, alt: float, wind_from: float, wind_kt: float) -> None:
        self._tm(ch).data(t, alt, wind_from, wind_kt)

    def shown(self, t: int) -> Telemetry | None:
        """The channel the station shows: the lowest with a fresh status (station rule)."""
        for c in sorted(self.ch):
            tm = self.ch[c]
            if tm.status_t >= 0 and t - tm.status_t <= self.fresh_ns:
                return tm
        return None

    # -- the pilot ---------------------------------------------------------------------------
    def stick(self, t: int, station: dict, scripted: bool, link_up: bool):
        """(pitch, roll, power) the pilot puts on the stick at t (power: added to the station's
        throttle), or None: the script's stick."""
        tm = self.shown(t) if link_up else None
        direct = tm is not None and tm.mode == _DIRECT
        if tm is not None and tm.mode in _TARGET_MODES:
            self.last_auto_targets = (tm.tgt_hdg, tm.tgt_alt)
        if not (self.enabled and direct and not scripted):
            self.direct_since = None
            if self.flying:
                self.flying = False
                self.events.append((t, {"state": "off"}))
            return None
        if self.direct_since is None:
            self.direct_since = t
        if not self.flying:
            if t - self.direct_since < round(self.p.takeover_s * NS):
                return None
            self._take_over(t, station)
        else:
            self._follow_script(t, station)
        self._decide(t, tm)
        while self.pending and self.pending[0][0] <= t:
            self.out = self.pending.popleft()[1]
        return self.out

    def _take_over(self, t: int, station: dict) -> None:
        """The targets the pilot holds: his own when he asked for DIRECT himself, else the
        ones the flight control last flew before it reverted (his own if it never did)."""
        own = (station["heading_deg"] % 360.0, float(station["altitude_ft"]))
        if station["mode"] == "DIRECT" or self.last_auto_targets is None:
            self.targets = own
        else:
            self.targets = self.last_auto_targets
        self._script_targets = own
        self.flying = True
        self.roll_trim = self.pitch_trim = 0.0
        self.pending.clear()
        self.out = (0.0, 0.0, 0.0)
        self.hdg_track.clear()
        self.last_t = None
        self.events.append((t, {"state": "flying",
                                "heading_deg": round(float(self.targets[0]), 2),
                                "altitude_ft": round(float(self.targets[1]), 1)}))

    def _follow_script(self, t: int, station: dict) -> None:
        """A new heading or altitude in the script is the pilot's new intention."""
        own = (station["heading_deg"] % 360.0, float(station["altitude_ft"]))
        if own != self._script_targets:
            self._script_targets = own
            self.targets = own
            self.events.append((t, {"state": "targets", "heading_deg": round(own[0], 2),
                                    "altitude_ft": round(own[1], 1)}))

    def _decide(self, t: int, tm: Telemetry) -> None:
        """One input, computed from the telemetry now and applied reaction_s later."""
        p = self.p
        dt = 0.0 if self.last_t is None else (t - self.last_t) / NS
        self.last_t = t
        pitch, roll, power = self.pending[-1][1] if self.pending else self.out
        t_from = t - self.window_ns
        # lateral: from the ground track and the wind, the heading and its rate
        pts = [x for x in tm.pos if x[0] >= t_from]
        hdg_rate = None
        if tm.nav_flags & _POS_VALID and len(pts) >= 4 and t - pts[-1][0] <= self.fresh_ns:
            vn, ve = _track_velocity(pts)
            an = vn - tm.wind_to[0] * KT_MPS  # the air velocity: its direction is the heading
            ae = ve - tm.wind_to[1] * KT_MPS
            hdg = math.atan2(ae, an) * DEG % 360.0
            prev = self.hdg_track[-1][1] if self.hdg_track else hdg
            self.hdg_track.append((t, prev + _wrap180(hdg - prev)))
            while self.hdg_track[0][0] < t_from:
                self.hdg_track.popleft()
            hdg_rate = _slope([((a - t) / NS, h) for a, h in self.hdg_track])
        if hdg_rate is not None:
            err = _wrap180(self.targets[0] - self.hdg_track[-1][1] % 360.0)
            want = _clamp(p.hdg_gain * err, -p.turn_rate_max, p.turn_rate_max)
            e_rate = want - hdg_rate
            self.roll_trim = _clamp(self.roll_trim + p.roll_trim_gain * e_rate * dt,
                                    -p.roll_trim_max, p.roll_trim_max)
            roll = _clamp(p.roll_gain * e_rate + self.roll_trim, -p.roll_max, p.roll_max)
        elif not tm.nav_flags & _POS_VALID:
            roll = self.roll_trim  # no track to fly by: hands steady where the wings were level
        # vertical: the altitude and its trend
        alts = [((a - t) / NS, h) for a, h in tm.alt if a >= t - self.vs_window_ns]
        vs = _slope(alts)
        if tm.nav_flags & _ALT_VALID and vs is not None and t - tm.data_t <= self.fresh_ns:
            vs *= 60.0
            want = _clamp(p.alt_gain * (self.targets[1] - alts[-1][1]), -p.vs_max, p.vs_max)
            e_vs = want - vs
            self.pitch_trim = _clamp(self.pitch_trim + p.pitch_trim_gain * e_vs * dt,
                                     -p.pitch_trim_max, p.pitch_trim_max)
            pitch = _clamp(p.pitch_gain * e_vs + self.pitch_trim, -p.pitch_max, p.pitch_max)
            power = p.climb_power * want  # power for the climb (or descent) asked
        self.pending.append((t + round(p.reaction_s * NS), (pitch, roll, power)))
