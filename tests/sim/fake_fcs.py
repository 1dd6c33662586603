# SPDX-License-Identifier: Apache-2.0
"""A stand-in flight control for the world's unit tests: it flies the pilot's stick straight to
the surfaces (DIRECT) and downlinks FCS_STATUS_A, NAV_POS_A and NAV_DATA_A made from the
world's own GPS and air-data frames, as nav_fcs would. Only for tests of the station side
(the pilot model); the real partition is flown in tests/flight/."""

from __future__ import annotations

import math

from ima.canbus.codec import MESSAGES

_STICK = MESSAGES["PILOT_STICK"]
_GPS_POS = MESSAGES["GPS_POS"]
_GPS_VEL = MESSAGES["GPS_VEL"]
_AIR = MESSAGES["AIR_DATA"]
_CMD = MESSAGES["ACT_CMD_A"]
_STATUS = MESSAGES["FCS_STATUS_A"]
_NAV_POS = MESSAGES["NAV_POS_A"]
_NAV_DATA = MESSAGES["NAV_DATA_A"]
MS = 1_000_000


class FakeFcs:
    """`injector(t_from, t_until)` for a LoopbackBus whose `sent` it reads. `mode_of_t(t_ns)`
    -> (mode, fallback, nav_flags) it reports, or None: silent; in DIRECT (mode 1) the
    surfaces are the stick, otherwise `cmd_otherwise` (elev, ail, rud, thr)."""

    def __init__(self, bus, mode_of_t, cmd_otherwise, targets=(90.0, 3000.0),
                 alt_error_ft: float = 0.0) -> None:
        self.bus = bus
        self.alt_error_ft = alt_error_ft  # what the downlinked altitude gets wrong
        self.mode_of_t = mode_of_t
        self.cmd_otherwise = cmd_otherwise
        self.targets = targets
        self.read = 0
        self.stick = None
        self.gps = None  # (t, lat, lon) of the last fix
        self.air = None  # alt
        self.gs = self.trk = 0.0
        self.cnt = 0

    def _catch_up(self) -> None:
        sent = self.bus.sent
        for t, fid, data in sent[self.read:]:
            if fid == _STICK.frame_id:
                self.stick = _STICK.decode(data)
            elif fid == _GPS_POS.frame_id:
                self.gps = (t, *_GPS_POS.decode(data))
            elif fid == _GPS_VEL.frame_id:
                v = _GPS_VEL.decode(data)
                if v[3] >= 2:
                    self.gs, self.trk = v[1], v[2]
                else:
                    self.gps = None
            elif fid == _AIR.frame_id:
                self.air = _AIR.decode(data)[1]
        self.read = len(sent)

    def __call__(self, t_from: int, t_until: int) -> list:
        if t_from % (50 * MS):
            return []
        self._catch_up()
        if self.mode_of_t(t_from) is None:
            return []
        mode, fb, flags = self.mode_of_t(t_from)
        if mode == 1 and self.stick is not None:
            pitch, roll, yaw, thr, _ = self.stick
            cmd = (-pitch, roll, yaw, thr)
        else:
            cmd = self.cmd_otherwise
        self.cnt = (self.cnt + 1) & 0xFF
        out = [(t_from, _CMD.frame_id, _CMD.encode(*cmd, self.cnt & 0xF)),
               (t_from, _STATUS.frame_id, _STATUS.encode(mode, 2, fb, flags, 0, 0, 0, self.cnt,
                                                         *self.targets))]
        if t_from % (100 * MS) == 0 and self.gps is not None and self.air is not None:
            # as nav does: the last fix carried forward to now with the GPS's own velocity
            t, lat, lon = self.gps
            age = (t_from - t) / 1e9
            a = math.radians(self.trk)
            lat += self.gs * 0.514444 * age * math.cos(a) / 6378137.0 * 180 / math.pi
            lon += self.gs * 0.514444 * age * math.sin(a) / (
                6378137.0 * math.cos(math.radians(lat))) * 180 / math.pi
            out += [(t_from, _NAV_POS.frame_id, _NAV_POS.encode(lat, lon)),
                    (t_from, _NAV_DATA.frame_id, _NAV_DATA.encode(self.air + self.alt_error_ft, 0.0, 0.0,
                                                           self.gs))]
        return out


def fly_with_fake_fcs(run_dir, script, seconds: float, mode_of_t, seed: int = 0,
                      alt_error_ft: float = 0.0, **opts):
    """The world in-process on a LoopbackBus with a FakeFcs; `script` a dict or a PilotScript.
    Returns the World (its files are in run_dir) and the bus."""
    from fakebus import LoopbackBus

    from imaworld import pilot
    from imaworld.world import Options, World

    if not isinstance(script, pilot.PilotScript):
        script = pilot.parse(script)
    bus = LoopbackBus(round(seconds * 1e9))
    w = World(bus, script, run_dir, Options(seed=seed, **opts))
    tr = w.trim
    bus.injector = FakeFcs(bus, mode_of_t, (tr["elev"], tr["ail"], tr["rud"], tr["thr"]),
                           alt_error_ft=alt_error_ft)
    w.run()
    return w, bus
