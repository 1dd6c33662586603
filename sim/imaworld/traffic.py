# SPDX-License-Identifier: Apache-2.0
"""Scripted traffic and the surveillance receiver that reports it (ADS-B In class).

Each intruder of the script (`traffic:`) appears at `t` at `range_m` on `bearing_deg` from
where the aircraft is then, `rel_alt_ft` above it, and flies straight and level on `track_deg`
at `gs_kt` until `until` (else to the end of the flight). Bearing and track are relative to
the aircraft's ground track at `t` (bearing 0: dead ahead; track 180: head-on), so that an
encounter is scripted whatever the route. The receiver sends one
TRAFFIC frame every `period_ms`: the nearest intruder within `range_m` of the aircraft,
relative to it (north, east, altitude difference, its track), or none (TFC_VALID 0)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ima.canbus.codec import MESSAGES

_TRAFFIC = MESSAGES["TRAFFIC"]
NS = 1_000_000_000
KT = 1852.0 / 3600.0


@dataclass(frozen=True)
class TrafficParams:
    period_ms: int = 200     # 5 Hz
    range_m: float = 10000.0  # intruders farther than this are not reported


@dataclass
class Intruder:
    t0_ns: int
    t1_ns: int | None
    spec: dict
    n0: float = 0.0  # where it appeared, metres north/east of the world's reference
    e0: float = 0.0
    alt0: float = 0.0
    track_deg: float = 0.0  # true, fixed when it appears
    appeared: bool = False
    active: bool = False


class Traffic:
    def __init__(self, specs: list[dict], params: TrafficParams = TrafficParams()) -> None:
        self.p = params
        self.intruders = [Intruder(round(s["t"] * NS), round(s["until"] * NS) if "until" in s
                                   else None, s) for s in specs]
        self.cnt = 0
        self.events: list[tuple[int, str, dict]] = []

    def _pos(self, i: Intruder, t_ns: int) -> tuple[float, float, float]:
        dt = (t_ns - i.t0_ns) / NS
        v = i.spec["gs_kt"] * KT
        trk = math.radians(i.track_deg)
        return i.n0 + v * dt * math.cos(trk), i.e0 + v * dt * math.sin(trk), i.alt0

    def sample(self, t_ns: int, own_n: float, own_e: float, own_alt_ft: float,
               own_track_deg: float):
        """The TRAFFIC frame at t_ns, the aircraft at (own_n, own_e) metres, own_alt_ft, on
        own_track_deg."""
        best = None
        for i in self.intruders:
            if t_ns < i.t0_ns:
                continue
            if i.t1_ns is not None and t_ns >= i.t1_ns:
                if i.active:
                    i.active = False
                    self.events.append((t_ns, "traffic", {"state": "gone", **_name(i)}))
                continue
            if not i.appeared:
                i.track_deg = (own_track_deg + i.spec["track_deg"]) % 360.0
                b = math.radians(own_track_deg + i.spec["bearing_deg"])
                i.n0 = own_n + i.spec["range_m"] * math.cos(b)
                i.e0 = own_e + i.spec["range_m"] * math.sin(b)
                i.alt0 = own_alt_ft + i.spec.get("rel_alt_ft", 0.0)
                i.appeared = i.active = True
                self.events.append((t_ns, "traffic", {"state": "appeared", **_name(i),
                                                      "alt_ft": round(i.alt0, 1)}))
            n, e, alt = self._pos(i, t_ns)
            d = math.hypot(n - own_n, e - own_e)
            if d <= self.p.range_m and (best is None or d < best[0]):
                best = (d, n - own_n, e - own_e, alt - own_alt_ft, i.track_deg)
        self.cnt = (self.cnt + 1) & 0x7F
        if best is None:
            return _TRAFFIC.frame_id, _TRAFFIC.encode(0, self.cnt, 0, 0, 0, 0)
        _, dn, de, dalt, trk = best
        return _TRAFFIC.frame_id, _TRAFFIC.encode(1, self.cnt, dn, de, dalt, trk % 360.0)

    def nearest_m(self, t_ns: int, own_n: float, own_e: float, own_alt_ft: float):
        """(horizontal m, vertical ft) to the nearest intruder in the air, or None."""
        out = None
        for i in self.intruders:
            if not i.active:
                continue
            n, e, alt = self._pos(i, t_ns)
            d = math.hypot(n - own_n, e - own_e)
            if out is None or d < out[0]:
                out = (d, abs(alt - own_alt_ft))
        return out


def _name(i: Intruder) -> dict:
    return {"intruder": i.spec.get("name", f"T{round(i.t0_ns / NS)}")}
