# SPDX-License-Identifier: Apache-2.0
"""Ground contact: a landing or a crash, bounces, the stop, and the wheel brakes.

The first contact of a main wheel (JSBSim's gear units 1 and 2, weight on wheels) is the
touchdown. It is a landing within LandingParams' limits (sink rate, bank, pitch: no nose wheel
first) and a crash beyond them. After it, a main gear off the ground for `bounce_s` with the
wheels `bounce_ft` above their touchdown height is a bounce; the first instant the ground speed
falls under `stopped_kt` is the stop. The brakes are commanded over CAN (BRAKE_CMD_A..C, sent
only while a flight-control channel brakes): the brake actuator follows the median of the
channels heard in the last `brake_fresh_s` (none: released) at its rate limit, on both main
wheels."""

from __future__ import annotations

import statistics
from dataclasses import dataclass

NS = 1_000_000_000


@dataclass(frozen=True)
class LandingParams:
    max_sink_fps: float = 10.0   # a harder contact breaks the gear: a crash
    max_bank_deg: float = 10.0   # a wing tip or one wheel first
    min_pitch_deg: float = -1.0  # the nose wheel first
    bounce_s: float = 0.3        # both main wheels off the ground this long after touchdown...
    bounce_ft: float = 1.0       # ... and this much higher: a bounce
    stopped_kt: float = 1.0
    brake_fresh_s: float = 0.2
    brake_rate: float = 2.0      # per second


class Ground:
    """The world's view of the wheels (fed every physics step near the ground)."""

    def __init__(self, params: LandingParams = LandingParams()) -> None:
        self.p = params
        self.touchdown: dict | None = None
        self.bounces = 0
        self.stopped: dict | None = None
        self._air_since: int | None = None
        self._td_agl = 0.0
        self._bounced_now = False
        self.brake_cmd: dict[int, tuple[int, float]] = {}  # channel -> (t_ns, command)
        self.brake = 0.0
        self.events: list[tuple[int, str, dict]] = []

    def step(self, t_ns: int, wow_main: bool, agl_ft: float, sink_fps: float, bank_deg: float,
             pitch_deg: float, gs_kt: float, lat: float, lon: float) -> str | None:
        """One physics step; returns a crash reason, or None."""
        p = self.p
        if self.touchdown is None:
            if not wow_main:
                return None
            fields = {"sink_fps": round(sink_fps, 2), "bank_deg": round(bank_deg, 2),
                      "pitch_deg": round(pitch_deg, 2), "gs_kt": round(gs_kt, 2),
                      "lat_deg": round(lat, 7), "lon_deg": round(lon, 7)}
            self.touchdown = {"t_ns": t_ns, **fields}
            self._td_agl = agl_ft
            if sink_fps > p.max_sink_fps:
                return f"hard landing: sink rate {sink_fps:.1f} ft/s"
            if abs(bank_deg) > p.max_bank_deg:
                return f"landing with {bank_deg:.1f} deg of bank"
            if pitch_deg < p.min_pitch_deg:
                return f"landing nose wheel first (pitch {pitch_deg:.1f} deg)"
            self.events.append((t_ns, "touchdown", fields))
            return None
        if wow_main:
            self._air_since = None
            self._bounced_now = False
        else:
            if self._air_since is None:
                self._air_since = t_ns
            if (not self._bounced_now and t_ns - self._air_since >= p.bounce_s * NS
                    and agl_ft > self._td_agl + p.bounce_ft):
                self._bounced_now = True
                self.bounces += 1
                self.events.append((t_ns, "bounce", {"agl_ft": round(agl_ft, 2)}))
        if self.stopped is None and wow_main and gs_kt < p.stopped_kt:
            self.stopped = {"t_ns": t_ns, "lat_deg": round(lat, 7), "lon_deg": round(lon, 7)}
            self.events.append((t_ns, "stopped", {"lat_deg": round(lat, 7),
                                                  "lon_deg": round(lon, 7)}))
        return None

    def brake_command(self, channel: int, t_ns: int, value: float) -> None:
        self.brake_cmd[channel] = (t_ns, value)

    def brake_step(self, t_ns: int, dt: float) -> float:
        """The brake actuator's position at t_ns (0..1)."""
        fresh = [v for t, v in self.brake_cmd.values() if t_ns - t <= self.p.brake_fresh_s * NS]
        want = statistics.median(fresh) if fresh else 0.0
        step = self.p.brake_rate * dt
        self.brake += max(-step, min(step, want - self.brake))
        return self.brake

    def summary(self) -> dict:
        return {"touchdown": self.touchdown, "bounces": self.bounces, "stopped": self.stopped}
