# SPDX-License-Identifier: Apache-2.0
"""Sensor models (GPS, AHRS, air data) turning the true state into CAN frames with errors."""

from __future__ import annotations

import itertools
import math
import zlib
from dataclasses import replace

import numpy as np

from ima.canbus.codec import MESSAGES

from .config import FT_TO_M, GPS_AUGMENTATION, AdcParams, AhrsParams, GpsParams, RadaltParams

R_EARTH_M = 6_378_137.0
MPS_TO_KT = 1.0 / 0.514444
DEG = 180.0 / math.pi

_GPS_POS = MESSAGES["GPS_POS"]
_GPS_VEL = MESSAGES["GPS_VEL"]
_AHRS_ATT = MESSAGES["AHRS_ATT"]
_AHRS_RATE = MESSAGES["AHRS_RATE"]
_AHRS_ACCEL = MESSAGES["AHRS_ACCEL"]
_AIR_DATA = MESSAGES["AIR_DATA"]
_RADALT = MESSAGES["RADALT"]


def normal_stream(seed: int, name: str, core=None):
    """A function returning standard normal draws, one per call, from a numpy PCG64 generator
    seeded by (seed, name): each sensor has its own stream, so adding draws to one sensor does
    not change another's. Draws come in blocks (far cheaper per value than random.gauss).
    With `core` (the module imaworld._core), a core.Normals over the same blocks: the same
    draws, which the C++ can take too."""
    gen = np.random.Generator(np.random.PCG64(np.random.SeedSequence(
        [seed & 0xFFFFFFFFFFFFFFFF, zlib.crc32(name.encode())])))

    def block():
        return gen.standard_normal(4096).tolist()

    if core is not None:
        return core.Normals(block)

    def blocks():
        while True:
            yield block()

    return itertools.chain.from_iterable(blocks()).__next__


def message_spec(m) -> tuple:
    """A message's layout as the C++ encodes it (sim/core/codec.cc)."""
    return (m.frame_id, m.length,
            tuple((s.start, s.length, s.signed, s.scale, s.offset) for s in m.signals))


class GaussMarkov:
    """First-order Gauss-Markov process sampled every dt: stationary, std `sigma`, time constant
    `tau`. Starts from a draw of its stationary distribution."""

    __slots__ = ("a", "q", "x", "n")

    def __init__(self, n, sigma: float, tau_s: float, dt_s: float) -> None:
        self.a = math.exp(-dt_s / tau_s) if tau_s > 0 else 0.0
        self.q = sigma * math.sqrt(1.0 - self.a * self.a)
        self.n = n
        self.x = sigma * n()

    def step(self) -> float:
        self.x = self.a * self.x + self.q * self.n()
        return self.x


class Gps:
    """GPS receiver: GPS_POS + GPS_VEL at each sample; state ok / lost / frozen; with an
    augmentation (config.GPS_AUGMENTATION) its errors and the fix it reports."""

    def __init__(self, p: GpsParams, seed: int, augmentation: str = "none") -> None:
        a = GPS_AUGMENTATION[augmentation]
        p = replace(p, bias_sigma_h_m=a["bias_sigma_h_m"], bias_sigma_v_m=a["bias_sigma_v_m"],
                    noise_h_m=a["noise_h_m"], noise_v_m=a["noise_v_m"])
        self.fix = a["fix"]
        self.p = p
        self.n = rng = normal_stream(seed, "gps")
        dt = p.period_ms / 1000.0
        self.bn = GaussMarkov(rng, p.bias_sigma_h_m, p.bias_tau_s, dt)
        self.be = GaussMarkov(rng, p.bias_sigma_h_m, p.bias_tau_s, dt)
        self.bd = GaussMarkov(rng, p.bias_sigma_v_m, p.bias_tau_s, dt)
        self.state = "ok"  # the pilot script's
        self.fault_state: str | None = None  # a fault's "lost" / "frozen": wins over the script
        self.offset: tuple[float, float] | None = None  # a fault's jump: north, east metres
        self.cnt = 0
        self.last: list[tuple[int, bytes]] = []

    @property
    def effective_state(self) -> str:
        return self.fault_state or self.state

    def sample(self, lat: float, lon: float, alt_ft: float, vn_fps: float,
               ve_fps: float) -> list[tuple[int, bytes]]:
        p, n = self.p, self.n
        bn, be, bd = self.bn.step(), self.be.step(), self.bd.step()  # biases run in every state
        state = self.fault_state or self.state
        if state == "frozen":
            return self.last  # same data, same counter
        self.cnt = (self.cnt + 1) & 0xFF
        if state == "lost":
            if p.lost_mode == "silent":
                return []
            out = [(_GPS_POS.frame_id, _GPS_POS.encode(0.0, 0.0)),
                   (_GPS_VEL.frame_id, _GPS_VEL.encode(0, 0.0, 0.0, 0, 2, self.cnt))]
            self.last = out
            return out
        dn = bn + p.noise_h_m * n()
        de = be + p.noise_h_m * n()
        du = bd + p.noise_v_m * n()
        if self.offset is not None:
            dn += self.offset[0]
            de += self.offset[1]
        mlat = lat + dn / R_EARTH_M * DEG
        mlon = lon + de / (R_EARTH_M * math.cos(lat / DEG)) * DEG
        if mlon >= 180.0:
            mlon -= 360.0
        elif mlon < -180.0:
            mlon += 360.0
        vn = vn_fps * FT_TO_M + p.noise_vel_mps * n()
        ve = ve_fps * FT_TO_M + p.noise_vel_mps * n()
        gs = math.hypot(vn, ve) * MPS_TO_KT
        trk = math.atan2(ve, vn) * DEG % 360.0
        if trk >= 359.995:
            trk = 0.0
        out = [(_GPS_POS.frame_id, _GPS_POS.encode(mlat, mlon)),
               (_GPS_VEL.frame_id, _GPS_VEL.encode(alt_ft + du / FT_TO_M, gs, trk, self.fix, p.sats,
                                                   self.cnt))]
        self.last = out
        return out


class Ahrs:
    """Attitude and heading reference: AHRS_ATT, AHRS_RATE, AHRS_ACCEL at each sample.

    With the C++ (`attach`), sample_now() reads the aircraft, draws and encodes in one call
    (sim/core/ahrs.cc), the same as sample() with the aircraft's values; the counter, the
    faults and the frames kept stay here."""

    def __init__(self, p: AhrsParams, seed: int, core=None) -> None:
        self.p = p
        self.n = rng = normal_stream(seed, "ahrs", core)
        dt = p.period_ms / 1000.0
        gm = GaussMarkov
        self.b_att = [gm(rng, p.bias_sigma_att_deg, p.bias_tau_s, dt) for _ in range(2)]
        self.b_hdg = gm(rng, p.bias_sigma_hdg_deg, p.bias_tau_s, dt)
        self.b_rate = [gm(rng, p.bias_sigma_rate_dps, p.bias_tau_s, dt) for _ in range(3)]
        self.b_acc = [gm(rng, p.bias_sigma_accel_g, p.bias_tau_s, dt) for _ in range(3)]
        self.cnt = 0
        self.fault_ops: list | None = None  # set by the fault injectors (faults.py)
        self._last_vals: tuple | None = None
        self._last_in_core = False  # the last values are the C++'s (core.last())
        self.last_frames: list[tuple[int, bytes]] = []
        self.core = None

    @property
    def last_vals(self) -> tuple | None:
        """The values of the last frames sent."""
        return self.core.last() if self._last_in_core else self._last_vals

    @last_vals.setter
    def last_vals(self, vals: tuple | None) -> None:
        self._last_vals = vals
        self._last_in_core = False

    def attach(self, core, lib: str, nodes) -> None:
        """Sample in C++ from now on (core: the module imaworld._core; nodes: the aircraft's
        phi, theta, psi, p, q, r, ax, ay, az property nodes)."""
        gms = [*self.b_att, self.b_hdg, *self.b_rate, *self.b_acc]
        P = self.p
        self.core = core.Ahrs(lib, nodes, self.n, [(g.a, g.q, g.x) for g in gms],
                              (P.noise_att_deg, P.noise_hdg_deg, P.noise_rate_dps,
                               P.noise_accel_g),
                              [message_spec(m) for m in (_AHRS_ATT, _AHRS_RATE, _AHRS_ACCEL)])

    def sample_now(self) -> list[tuple[int, bytes]]:
        """sample() of the aircraft's values now, in C++ (after attach())."""
        core = self.core
        if self.fault_ops is None:
            c = (self.cnt + 1) & 0xFF
            out = core.frames(c)
            if out is not None:
                self.cnt = c
                self.last_frames = out
                self._last_in_core = True
                return out
            return self._emit(core.last())  # a value not finite: encoding it raises, as ever
        if self._last_in_core:  # the values of the last frames sent, before the next draw
            self.last_vals = core.last()
        return self._emit(core.vals())

    def sample(self, phi: float, theta: float, psi: float, p_: float, q: float, r: float,
               ax: float, ay: float, az: float) -> list[tuple[int, bytes]]:
        """Angles in degrees, rates in rad/s, specific force in g (body axes, z down)."""
        P, n = self.p, self.n
        ba, br, bc = self.b_att, self.b_rate, self.b_acc
        roll = phi + ba[0].step() + P.noise_att_deg * n()
        if roll > 180.0:
            roll -= 360.0
        elif roll < -180.0:
            roll += 360.0
        pitch = theta + ba[1].step() + P.noise_att_deg * n()
        hdg = (psi + self.b_hdg.step() + P.noise_hdg_deg * n()) % 360.0
        if hdg >= 359.995:
            hdg = 0.0
        nr, na = P.noise_rate_dps, P.noise_accel_g
        # the errors are drawn in every state: a fault leaves the streams as they were
        vals = (roll, pitch, hdg,
                p_ * DEG + br[0].step() + nr * n(), q * DEG + br[1].step() + nr * n(),
                r * DEG + br[2].step() + nr * n(),
                ax + bc[0].step() + na * n(), ay + bc[1].step() + na * n(),
                az + bc[2].step() + na * n())
        return self._emit(vals)

    def _emit(self, vals: tuple) -> list[tuple[int, bytes]]:
        """The frames of a sample's values, faults applied, the counter counted."""
        fill = None
        if self.fault_ops is not None:
            vals, frames, fill = self._faulty(vals)
            if frames:
                return frames  # frozen: the last frames again, counters included
        self.cnt = c = (self.cnt + 1) & 0xFF
        out = [
            (_AHRS_ATT.frame_id, _AHRS_ATT.encode(vals[0], vals[1], vals[2], 3, c)),
            (_AHRS_RATE.frame_id, _AHRS_RATE.encode(vals[3], vals[4], vals[5], 3, c)),
            (_AHRS_ACCEL.frame_id, _AHRS_ACCEL.encode(vals[6], vals[7], vals[8], 3, c)),
        ]
        if fill is not None:
            fill[1] = out
        self.last_vals = vals
        self.last_frames = out
        return out

    def _faulty(self, vals: tuple) -> tuple[tuple, list | None, list | None]:
        """The values the active faults make of a sample, in the order they were applied:
        ("stuck", [values, frames], counter frozen) replaces every value (or sends the frames
        again); ("bias", index, value) adds to one. A stuck AHRS with nothing sent before its
        spell repeats the spell's first sample: that one fills the holder (returned)."""
        v = list(vals)
        frames = fill = None
        for op in self.fault_ops:
            if op[0] == "stuck":
                held = op[1]
                if held[0] is None:
                    held[0] = tuple(v)
                    fill = held if op[2] else None
                    frames = None
                else:
                    v = list(held[0])
                    frames = held[1] if op[2] else None
            else:
                i, b = op[1], op[2]
                v[i] += b
                frames = None
        if v[0] > 180.0:
            v[0] -= 360.0
        elif v[0] < -180.0:
            v[0] += 360.0
        v[1] = max(-90.0, min(90.0, v[1]))
        v[2] %= 360.0
        if v[2] >= 359.995:
            v[2] = 0.0
        return tuple(v), frames, fill


# ISA sea-level pressure and speed of sound, for the pitot-static relations below.
P0_PA = 101325.0
A0_KT = 661.4786


def impact_pressure(cas_kt: float) -> float:
    """Pitot minus static pressure (Pa) at a calibrated airspeed (subsonic, compressible)."""
    return P0_PA * ((1.0 + 0.2 * (cas_kt / A0_KT) ** 2) ** 3.5 - 1.0)


def cas_from_impact(qc_pa: float) -> float:
    """The calibrated airspeed an air-data computer reads from an impact pressure (>= 0)."""
    if qc_pa <= 0.0:
        return 0.0
    return A0_KT * math.sqrt(5.0 * ((qc_pa / P0_PA + 1.0) ** (2.0 / 7.0) - 1.0))


def static_pressure(palt_ft: float) -> float:
    """ISA static pressure (Pa) at a pressure altitude (troposphere)."""
    return P0_PA * (1.0 - 6.8755856e-6 * palt_ft) ** 5.2558797


class AirData:
    """Air data computer: AIR_DATA (calibrated airspeed, baro altitude, vertical speed).

    With the C++ (`attach`), sample_now() reads the aircraft, draws and encodes in one call
    (sim/core/adc.cc), the same as sample() with the aircraft's values."""

    def __init__(self, p: AdcParams, seed: int, core=None) -> None:
        self.p = p
        self.n = rng = normal_stream(seed, "adc", core)
        dt = p.period_ms / 1000.0
        self.b_ias = GaussMarkov(rng, p.bias_sigma_ias_kt, p.bias_tau_s, dt)
        self.b_alt = GaussMarkov(rng, p.bias_sigma_alt_ft, p.bias_tau_s, dt)
        self.cnt = 0
        self.core = None

    def attach(self, core, lib: str, nodes) -> None:
        """Sample in C++ from now on (nodes: the aircraft's cas, palt, hdot property nodes)."""
        P = self.p
        self.core = core.Adc(lib, nodes, self.n,
                             [(g.a, g.q, g.x) for g in (self.b_ias, self.b_alt)],
                             (P.noise_ias_kt, P.noise_alt_ft, P.noise_vs_fpm),
                             message_spec(_AIR_DATA))

    def sample_now(self, cas_kt: float | None = None) -> list[tuple[int, bytes]]:
        """sample() of the aircraft's values now (cas_kt given: that airspeed), in C++."""
        self.cnt = c = (self.cnt + 1) & 0xF
        out = self.core.frames(c, cas_kt)
        if out is None:  # a value not finite: encoding it raises, as ever
            ias, alt, vs = self.core.last()
            return [(_AIR_DATA.frame_id, _AIR_DATA.encode(ias, alt, vs, 1, c))]
        return out

    def sample(self, cas_kt: float, palt_ft: float, hdot_fps: float) -> list[tuple[int, bytes]]:
        P, n = self.p, self.n
        self.cnt = c = (self.cnt + 1) & 0xF
        ias = max(0.0, cas_kt + self.b_ias.step() + P.noise_ias_kt * n())
        alt = palt_ft + self.b_alt.step() + P.noise_alt_ft * n()
        vs = hdot_fps * 60.0 + P.noise_vs_fpm * n()
        return [(_AIR_DATA.frame_id, _AIR_DATA.encode(ias, alt, vs, 1, c))]


class RadarAltimeter:
    """Radar altimeter: RADALT, the height of the main wheels above the ground (the antenna
    is calibrated to read 0 on the wheels), below its range only (nothing is sent above it)."""

    def __init__(self, p: RadaltParams, seed: int) -> None:
        self.p = p
        self.n = normal_stream(seed, "radalt")
        self.cnt = 0

    def sample(self, agl_ft: float) -> list[tuple[int, bytes]]:
        h = agl_ft - self.p.gear_ft
        if not h < self.p.range_ft:
            return []
        self.cnt = c = (self.cnt + 1) & 0x7F
        h = max(0.0, h + self.p.noise_ft * self.n())
        return [(_RADALT.frame_id, _RADALT.encode(h, 1, c))]

