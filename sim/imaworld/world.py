# SPDX-License-Identifier: Apache-2.0
"""The world process: physics, sensors, actuators, C2 link and pilot station, in bus lockstep."""

from __future__ import annotations

import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from ima.canbus import proto
from ima.canbus.client import BusError
from ima.canbus.codec import BY_ID, MESSAGES, choices

from . import core, stepper
from .actuators import CHANNELS, Actuators, LowestLiveChannel, VotingSelector, safe_position
from .config import DEFAULT, NS, VotingParams, WorldParams
from .faults import WorldFaults
from .faultspec import FaultSpec
from .fdm import Aircraft
from .landing import Ground
from .physics import NEAR_GROUND_FT, Crash, Physics
from .pilot import LAT_MODE_CODES, MODE_CODES, VERT_MODE_CODES, PilotScript
from .pilot_model import PilotModel
from .sensors import Ahrs, AirData, Gps, RadarAltimeter, cas_from_impact, static_pressure
from .traffic import Traffic
from .uplink import Uplink

FLUSH_EVERY_NS = NS // 2  # emulated time between two flushes of the world's traces

INF = 1 << 62

_PILOT_MODE = MESSAGES["PILOT_MODE"]
_PILOT_TARGETS = MESSAGES["PILOT_TARGETS"]
_PILOT_STICK = MESSAGES["PILOT_STICK"]
_ACT_STATUS = MESSAGES["ACT_STATUS"]
# What the world does with a frame it receives, by identifier: (kind, channel, decode), for
# each redundancy channel's message of each kind.
_ACT, _BRAKE, _STATUS, _POS, _DATA = range(5)
_HANDLED = {MESSAGES[f"{name}_{c}"].frame_id: (kind, i, MESSAGES[f"{name}_{c}"].decode)
            for kind, name in ((_ACT, "ACT_CMD"), (_BRAKE, "BRAKE_CMD"), (_STATUS, "FCS_STATUS"),
                               (_POS, "NAV_POS"), (_DATA, "NAV_DATA"))
            for i, c in enumerate(CHANNELS)}
# The world leaves the quanta before its next task ungranted (World._delivered) only this far
# from every limit a crash is judged by, and for SKIP_MAX_NS at most: no aircraft gets from
# there to a limit within that time, so a crash is found in the quantum it happens in, and the
# run stops there, as with every quantum granted. (Should one be found later all the same,
# its event says by how much: found_late_ns.)
SKIP_MAX_NS = 20_000_000
SKIP_MIN_AGL_FT = 100.0
SKIP_ROLL_MARGIN_DEG = 15.0
SKIP_CAS_MARGIN_KT = 10.0
SKIP_LOAD_MARGIN_G = 1.0
FCS_MODES = choices("FCS_STATUS_A", "FCS_MODE_A")
FCS_FALLBACKS = choices("FCS_STATUS_A", "FCS_FALLBACK_A")


@dataclass
class Options:
    seed: int = 0
    turbulence: str = "none"
    wind_kt: float | None = None  # None: the script's wind, else calm
    wind_from_deg: float | None = None
    terrain_ft: float = 500.0
    status: bool = False
    # Flight-control replicas commanding the actuators (ACT_CMD_A..), 1..3: the actuators
    # vote over them as `voting` says (required with channels). None: not told, so one
    # replica, simplex: the lowest live channel is used, nothing is voted.
    channels: int | None = None
    voting: VotingParams | None = None
    faults: list[FaultSpec] = field(default_factory=list)  # --fault, in command-line order
    # Test-only switches (--test-switch): "no-vote-out" makes the voter never vote a
    # channel out, to show that a campaign oracle can fail; "every-quantum" makes the world
    # ask for every quantum (see World._delivered), to show that skipping them changes nothing;
    # "python-only" makes it run its Python where it has C++ (core.py: the physics steps, the
    # AHRS, the air data, the truth), to show that the C++ changes nothing.
    test_switches: tuple[str, ...] = ()
    # Mission plan images the station uplinks (--uplink T:FILE): [(t_ns, image)]
    uploads: list[tuple[int, bytes]] = field(default_factory=list)


def _r(x: float, n: int) -> float | None:
    """Round for the output files (fixed precision keeps runs byte-identical and small)."""
    if x != x or x in (math.inf, -math.inf):
        return None
    v = round(x, n)
    return 0.0 if v == 0 else v  # no "-0.0"


def _named(counts: dict[int, int]) -> dict[str, int]:
    """Frame counts by identifier, by name (the DBC's, else the identifier in hex)."""
    out: dict[str, int] = {}
    for fid, n in counts.items():
        m = BY_ID.get(fid)
        name = m.name if m is not None else f"0x{fid:08x}"
        out[name] = out.get(name, 0) + n
    return dict(sorted(out.items()))


class World(Physics):
    """Everything outside the avionics. `bus` is a BusClient-like object (wait_tick, send,
    done, stop); the world is a LOCKSTEP client and runs until the bus stops or it crashes."""

    def __init__(self, bus, script: PilotScript, run_dir: str | Path, opts: Options,
                 params: WorldParams = DEFAULT, status_out=None) -> None:
        self.bus = bus
        self.script = script
        self.p = params
        self.opts = opts
        self.run_dir = Path(run_dir)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.status_out = status_out
        seed = opts.seed
        if opts.wind_kt is not None:
            wind = (opts.wind_kt, 270.0 if opts.wind_from_deg is None else opts.wind_from_deg)
        elif script.wind:
            wind = (script.wind.get("speed_kt", 0.0), script.wind.get("from_deg", 270.0))
        else:
            wind = (0.0, 270.0)
        self.wind = wind
        self.ac = Aircraft(params, script.start, seed, opts.terrain_ft, wind)
        # the world's C++ (core.py), unless the test switch python-only asks for its Python
        self._core = None if "python-only" in opts.test_switches else core.load()
        if self._core is None and "python-only" not in opts.test_switches:
            core.unavailable("stepping and sampling", core.why_not())
        self.trim = self.ac.trim()
        turb = opts.turbulence
        if turb not in params.atmosphere.turbulence:
            raise ValueError(f"unknown turbulence {turb!r}")
        self.ac.set_turbulence(*params.atmosphere.turbulence[turb])
        tr = self.trim
        self.voting = opts.voting
        self.act = Actuators(params.actuators, (tr["elev"], tr["ail"], tr["rud"], tr["thr"]),
                             self._selector(opts.channels, opts.voting, params,
                                            "no-vote-out" in opts.test_switches))
        self.ac.set_controls(*self.act.pos)
        self.gps = Gps(params.gps, seed, script.gps_augmentation)
        self.ahrs = Ahrs(params.ahrs, seed, self._core)
        self.adc = AirData(params.adc, seed, self._core)
        self.radalt = RadarAltimeter(params.radalt, seed)
        # station
        self.station = dict(script.initial)
        self.pil_cnt = 0
        self.stk_cnt = 0
        self.fcs_status: list[tuple[int, int, int] | None] = [None, None, None]  # (t, mode, fb)
        self.fcs_last: tuple[int, int] | None = None
        self.pilot_model = PilotModel(params.pilot_model, script.pilot_model)
        self.uplink = Uplink(opts.uploads) if opts.uploads or script.has_mission else None
        self._uplink_ev_done = 0
        self.traffic = Traffic(script.traffic) if script.traffic else None
        self._truth_core = None  # the truth lines in C++ (_attach_sensors)
        if self._core is not None:
            self._attach_sensors()
        self.ground = Ground()
        self._ground_ev_done = 0
        self._traffic_ev_done = 0
        self._pm_done = 0
        self._stick_scripted = False  # the script flies the stick itself (see _scripted)
        # bookkeeping
        self.hz = params.physics_hz
        self.dt = 1.0 / self.hz
        self.n = 0  # physics steps done: the state is at t_n = n * NS // hz
        self.next_step_t = NS // self.hz
        self.t_now = 0
        self.sent: dict[int, int] = {}  # frames by identifier (named in world.json)
        self.received: dict[int, int] = {}
        self.crash: tuple[int, str] | None = None
        self.stop_reason: str | None = None
        self.interrupted = False  # set by a signal: stop at the end of the quantum
        self.t_end = 0
        self.events_f = open(self.run_dir / "world.jsonl", "w")
        self.truth_f = open(self.run_dir / "truth.jsonl", "w")
        self._act_trans_done = 0
        self._vote_ev_done = 0
        self._evt_idx = 0
        self._evt_times = [round(e["t"] * NS) for e in script.events]
        self.event("world", "start", aircraft=params.aircraft, seed=seed,
                   turbulence=turb, wind_kt=_r(wind[0], 3), wind_from_deg=_r(wind[1], 3),
                   terrain_ft=_r(opts.terrain_ft, 3),
                   trim={k: _r(v, 6) for k, v in self.trim.items()},
                   start=script.start)
        self.faults = WorldFaults(opts.faults, self, params.faults) if opts.faults else None
        self._tasks = self._make_tasks()
        # the physics steps in C++ (or the module cannot drive this JSBSim: stepper.make says
        # why on stderr)
        self._stepper = (None if self._core is None else
                         stepper.make(self._core, self.ac, self.act, params.limits,
                                      NEAR_GROUND_FT, self.hz))
        self.skip_quanta = "every-quantum" not in opts.test_switches  # see _delivered()
        self._serving_t = 0  # the start of the quantum being served (the stop, at the end)

    @staticmethod
    def _selector(channels: int | None, vp: VotingParams | None, params: WorldParams,
                  never_vote_out: bool = False):
        if channels is None:
            return LowestLiveChannel()
        if channels not in (1, 2, 3):
            raise ValueError(f"channels must be 1, 2 or 3, not {channels!r}")
        if vp is None:
            raise ValueError("voted channels need the voting parameters (Options.voting)")
        return VotingSelector(channels, tuple(vp.thresholds), vp.persist,
                              round(vp.offset_s * NS), round(vp.period_s * NS),
                              safe_position(params.actuators), never_vote_out)

    # -- output --------------------------------------------------------------------------
    def event(self, src: str, kind: str, t_ns: int | None = None, **fields) -> None:
        rec = {"t_ns": self.t_now if t_ns is None else t_ns, "node": "world", "src": src,
               "kind": kind, **fields}
        self.events_f.write(json.dumps(rec, separators=(",", ":")) + "\n")

    def _send(self, t_ns: int, frames) -> None:
        send, sent = self.bus.send, self.sent
        for fid, data in frames:
            send(fid, data, t_ns)
            sent[fid] = sent.get(fid, 0) + 1

    def fcs_mode(self) -> tuple[str | None, str | None]:
        """What the station shows: the lowest FCS channel heard recently, else the last heard."""
        fresh = round(self.p.station.downlink_fresh_s * NS)
        for st in self.fcs_status:
            if st is not None and self.t_now - st[0] <= fresh:
                return FCS_MODES.get(st[1], str(st[1])), FCS_FALLBACKS.get(st[2], str(st[2]))
        if self.fcs_last is None:
            return None, None
        m, fb = self.fcs_last
        return FCS_MODES.get(m, str(m)), FCS_FALLBACKS.get(fb, str(fb))

    def link_up(self) -> bool:
        """The C2 link as it is: the script's state, unless a c2_loss fault has it down."""
        return self.station["c2_link"] == "up" and not (self.faults and self.faults.c2_down)

    def c2_link(self) -> str:
        """The C2 link as the truth records it."""
        return "up" if self.link_up() else "down"

    def truth(self) -> dict:
        g = self.ac.get
        pos = self.act.pos
        vn, ve = g["vn"](), g["ve"]()
        mode, fb = self.fcs_mode()
        return {
            "t_ns": self.t_now,
            "lat_deg": _r(g["lat"](), 7), "lon_deg": _r(g["lon"](), 7),
            "alt_ft": _r(g["alt"](), 2), "agl_ft": _r(g["agl"](), 2),
            "airspeed_kt": _r(g["cas"](), 3), "tas_kt": _r(g["tas"](), 3),
            "gs_kt": _r(math.hypot(vn, ve) / 1.6878098571011957, 3),
            "heading_deg": _r(g["psi"]() % 360.0, 3),
            "track_deg": _r(math.degrees(math.atan2(ve, vn)) % 360.0, 3),
            "roll_deg": _r(g["phi"](), 3), "pitch_deg": _r(g["theta"](), 3),
            "vs_fpm": _r(g["hdot"]() * 60.0, 1),
            "elev": _r(pos[0], 4), "ail": _r(pos[1], 4), "rud": _r(pos[2], 4),
            "thr": _r(pos[3], 4),
            "fcs_mode": mode, "fcs_fallback": fb,
            "c2_link": self.c2_link(), "gps": self.gps.effective_state,
            "wind_n_kt": _r(g["wind_n"]() / 1.6878098571011957, 3),
            "wind_e_kt": _r(g["wind_e"]() / 1.6878098571011957, 3),
            **self._traffic_truth(),
        }

    def _traffic_truth(self) -> dict:
        """With scripted traffic: the separation from the nearest intruder (None: none yet)."""
        if self.traffic is None:
            return {}
        n, e = self._own_ne()
        near = self.traffic.nearest_m(self.t_now, n, e, self.ac.get["alt"]())
        return {"traffic_h_m": _r(near[0], 1) if near else None,
                "traffic_v_ft": _r(near[1], 1) if near else None}

    # -- periodic work -------------------------------------------------------------------
    def _make_tasks(self) -> list[list]:
        p = self.p
        ms = 1_000_000
        tasks = [
            [self._next_event_t(), 0, self._pilot_events, self._next_event_t],
            [0, p.gps.period_ms * ms, self._gps],
            [0, p.ahrs.period_ms * ms, self._ahrs],
            [0, p.adc.period_ms * ms, self._adc],
            [0, p.radalt.period_ms * ms, self._radalt],
            [0, p.actuators.status_period_ms * ms, self._act_status],
            [0, p.station.mode_period_ms * ms, self._uplink_mode],
            [0, p.station.stick_period_ms * ms, self._uplink_stick],
            [0, p.truth_period_ms * ms, self._truth],
        ]
        if self.uplink is not None:
            tasks.append([0, self.uplink.p.gap_ms * ms, self._uplink_plan])
        if self.traffic is not None:
            tasks.append([0, self.traffic.p.period_ms * ms, self._traffic])
        if self.status_out is not None:
            tasks.append([0, NS, self._status])
        if self.faults is not None:
            # first at an instant: a spell that starts then acts on that instant's samples
            tasks.insert(0, [self.faults.next_t(), 0, self.faults.due, self.faults.next_t])
        return tasks

    def _next_event_t(self) -> int:
        i = self._evt_idx
        return self._evt_times[i] if i < len(self._evt_times) else INF

    def _pilot_events(self, t: int) -> None:
        evs = self.script.events
        while self._evt_idx < len(evs) and self._evt_times[self._evt_idx] <= t:
            e = evs[self._evt_idx]
            self._evt_idx += 1
            old = self.station
            self.station = PilotScript.apply(old, e)
            if "mode" in e:
                self._stick_scripted = False
            if "stick" in e:
                self._stick_scripted = True
            if "mission" in e and self.uplink is not None:
                self.uplink.command(t, e["mission"])
            fields = {k: v for k, v in e.items() if k != "t"}
            self.event("pilot", "pilot_event", **fields)
            if self.station["c2_link"] != old["c2_link"]:
                self.event("c2", "c2_link", state=self.station["c2_link"])
            if self.station["gps"] != old["gps"]:
                self.gps.state = self.station["gps"]
                self.event("gps", "sensor_state", sensor="gps", state=self.gps.state)
            if e.get("wind") is not None:
                w = e["wind"]
                self.wind = (w.get("speed_kt", self.wind[0]), w.get("from_deg", self.wind[1]))
                self.ac.set_wind(*self.wind)
                self.event("world", "wind", speed_kt=self.wind[0], from_deg=self.wind[1])

    def _attach_sensors(self) -> None:
        """What samples and records in C++: the AHRS, the air data, and the truth without
        traffic (the same draws, frames and lines)."""
        node, mod = self.ac.node, self._core
        try:
            lib = core.jsbsim_library(self.ac.fdm)
            self.ahrs.attach(mod, lib, [node[k] for k in ("phi", "theta", "psi", "p", "q", "r",
                                                          "ax", "ay", "az")])
            self.adc.attach(mod, lib, [node[k] for k in ("cas", "palt", "hdot")])
            if self.traffic is None:
                self._truth_core = mod.Truth(
                    lib, [node[k] for k in ("lat", "lon", "alt", "agl", "cas", "tas", "vn", "ve",
                                            "psi", "phi", "theta", "hdot", "wind_n", "wind_e")],
                    math.hypot, math.atan2)
        except core.REFUSALS as e:
            self.ahrs.core = self.adc.core = self._truth_core = None
            core.unavailable("sampling and recording", str(e))

    def _gps(self, t: int) -> None:
        g = self.ac.get
        self._send(t, self.gps.sample(g["lat"](), g["lon"](), g["alt"](), g["vn"](), g["ve"]()))

    def _ahrs(self, t: int) -> None:
        if self.ahrs.core is not None:
            self._send(t, self.ahrs.sample_now())
            return
        g = self.ac.get
        self._send(t, self.ahrs.sample(g["phi"](), g["theta"](), g["psi"](), g["p"](), g["q"](),
                                       g["r"](), g["ax"](), g["ay"](), g["az"]()))

    def _adc(self, t: int) -> None:
        g = self.ac.get
        pt = self.faults.pitot_pt if self.faults else None
        if self.adc.core is not None:
            self._send(t, self.adc.sample_now(
                None if pt is None else cas_from_impact(pt - static_pressure(g["palt"]()))))
            return
        cas = g["cas"]()
        if pt is not None:  # blocked pitot: the trapped total pressure against the static
            cas = cas_from_impact(pt - static_pressure(g["palt"]()))
        self._send(t, self.adc.sample(cas, g["palt"](), g["hdot"]()))

    def _radalt(self, t: int) -> None:
        frames = self.radalt.sample(self.ac.get["agl"]())
        if frames:
            self._send(t, frames)

    def _act_status(self, t: int) -> None:
        pos = self.act.pos
        self._send(t, [(_ACT_STATUS.frame_id,
                        _ACT_STATUS.encode(pos[0], pos[1], pos[2], pos[3], self.act.state))])

    def _uplink_mode(self, t: int) -> None:
        st = self.station
        if not self.link_up():
            return
        self.pil_cnt = (self.pil_cnt + 1) & 0xFF
        mode = "DIRECT" if self.faults and self.faults.disengage else st["mode"]
        self._send(t, [
            (_PILOT_MODE.frame_id, _PILOT_MODE.encode(
                MODE_CODES[mode], LAT_MODE_CODES[st["lat_mode"]],
                VERT_MODE_CODES[st["vert_mode"]], self.pil_cnt)),
            (_PILOT_TARGETS.frame_id, _PILOT_TARGETS.encode(
                st["heading_deg"] % 360.0, st["altitude_ft"], st["airspeed_kt"], st["vs_fpm"])),
        ])
        if self.uplink is not None:
            self._send(t, [self.uplink.command_frame()])

    def _own_ne(self) -> tuple[float, float]:
        """The aircraft's position in metres north and east of the script's start."""
        g, s = self.ac.get, self.script.start
        k = math.radians(1.0) * 6371008.8
        return ((g["lat"]() - s["lat_deg"]) * k,
                ((g["lon"]() - s["lon_deg"] + 180.0) % 360.0 - 180.0) * k
                * math.cos(math.radians(s["lat_deg"])))

    def _traffic(self, t: int) -> None:
        n, e = self._own_ne()
        g = self.ac.get
        track = math.degrees(math.atan2(g["ve"](), g["vn"]())) % 360.0
        self._send(t, [self.traffic.sample(t, n, e, g["alt"](), track)])
        for te, kind, f in self.traffic.events[self._traffic_ev_done:]:
            self.event("traffic", kind, t_ns=te, **f)
        self._traffic_ev_done = len(self.traffic.events)

    def _uplink_plan(self, t: int) -> None:
        up = self.uplink
        frames = up.due(t, self.link_up(), lambda _t: self.station["uplink"] == "corrupt")
        if frames:
            self._send(t, frames)
        for te, kind, f in up.events[self._uplink_ev_done:]:
            self.event("station", kind, t_ns=te, **f)
        self._uplink_ev_done = len(up.events)

    def _scripted(self) -> bool:
        """The script flies the stick itself: it asks for DIRECT and has given a stick input
        since it last changed the mode. Otherwise the pilot model may fly it."""
        return self._stick_scripted and self.station["mode"] == "DIRECT"

    def _uplink_stick(self, t: int) -> None:
        st = self.station
        up = self.link_up()
        pm = self.pilot_model.stick(t, st, self._scripted(), up)
        if len(self.pilot_model.events) != self._pm_done:
            for te, f in self.pilot_model.events[self._pm_done:]:
                self.event("pilot", "pilot_model", t_ns=te, **f)
            self._pm_done = len(self.pilot_model.events)
        if not up:
            return
        s = st["stick"]
        thr = s["throttle"] if s["throttle"] is not None else self.trim["thr"]
        if pm is None:
            pitch, roll = s["pitch"], s["roll"]
        else:
            pitch, roll = pm[0], pm[1]
            thr = min(max(thr + pm[2], 0.0), 1.0)
        self.stk_cnt = (self.stk_cnt + 1) & 0xF
        self._send(t, [(_PILOT_STICK.frame_id, _PILOT_STICK.encode(
            pitch, roll, s["yaw"], thr, self.stk_cnt))])

    def _truth(self, t: int) -> None:
        tc = self._truth_core
        if tc is not None:
            mode, fb = self.fcs_mode()
            line = tc.line(self.t_now, self.act.pos, mode, fb, self.c2_link(),
                           self.gps.effective_state)
            if line is not None:
                self.truth_f.write(line)
                return
        self.truth_f.write(json.dumps(self.truth(), separators=(",", ":")) + "\n")

    def _status(self, t: int) -> None:
        g = self.ac.get
        line = {"t_s": t / NS, "alt_ft": _r(g["alt"](), 1), "airspeed_kt": _r(g["cas"](), 1),
                "heading_deg": _r(g["psi"]() % 360.0, 1), "mode": self.fcs_mode()[0]}
        self.status_out.write(json.dumps(line) + "\n")

    # -- frames in -----------------------------------------------------------------------
    def _frames(self, frames) -> None:
        rcv = self.received
        link_up = self.link_up()
        pm = self.pilot_model if self.pilot_model.enabled else None
        handled = _HANDLED
        for f in frames:
            fid = f.id
            rcv[fid] = rcv.get(fid, 0) + 1
            h = handled.get(fid)
            if h is None:
                continue
            kind, ch, decode = h
            if kind == _ACT:
                e, ai, ru, th, _cnt = decode(f.data)
                self.act.command(ch, f.t_ns, (e, ai, ru, th))
            elif kind == _BRAKE:
                self.ground.brake_command(ch, f.t_ns, decode(f.data)[0])
            elif not link_up:
                continue
            elif kind == _STATUS:
                v = decode(f.data)
                self.fcs_status[ch] = (f.t_ns, v[0], v[2])
                self.fcs_last = (v[0], v[2])
                if pm is not None:
                    pm.status(ch, f.t_ns, v[0], v[2], v[3], v[8], v[9])
            elif pm is None:
                continue
            elif kind == _POS:
                lat, lon = decode(f.data)
                pm.nav_pos(ch, f.t_ns, lat, lon)
            else:
                alt, wdir, wspd, _gs = decode(f.data)
                pm.nav_data(ch, f.t_ns, alt, wdir, wspd)

    # -- skipped quanta ------------------------------------------------------------------
    # Far from the limits of a crash, the world asks for no quantum before its next task (its
    # DONE says when: the bus then grants it none ending at or before that instant). The
    # frames the bus delivered at the start of the quanta it was not granted come before its
    # next TICK; each is applied at the quantum start that delivered it (the first at or after
    # its end on the wire), the physics advanced to that instant first: what a world granted
    # every quantum does.
    @staticmethod
    def _delivery(frame, q: int) -> int:
        """The quantum start that delivered a frame: the first at or after its end on the wire."""
        return -(-frame.t_ns // q) * q

    def _delivered(self, frames, q: int) -> None:
        i, n = 0, len(frames)
        while i < n:
            d = self._delivery(frames[i], q)
            j = i + 1
            while j < n and self._delivery(frames[j], q) == d:
                j += 1
            self.advance(d)
            self._frames(frames if i == 0 and j == n else frames[i:j])
            i = j

    def _far_from_the_limits(self) -> bool:
        g, lim = self.ac.get, self.p.limits
        return (g["agl"]() > SKIP_MIN_AGL_FT
                and abs(g["phi"]()) < lim.max_roll_deg - SKIP_ROLL_MARGIN_DEG
                and g["cas"]() < lim.max_cas_kt - SKIP_CAS_MARGIN_KT
                and abs(g["nz"]()) < lim.max_load_g - SKIP_LOAD_MARGIN_G)  # NaN: False

    def _to_the_stop(self, q: int) -> None:
        """The bus ended the run at its stop instant after quanta the world was not granted: the
        frames delivered before that instant are applied and the physics flown up to it, as a
        world granted them all would have."""
        bus = self.bus
        stop = bus.stop_t_ns
        if stop is None or stop <= self.t_end:
            return
        self._serving_t = stop
        frames = [f for f in bus.unticked if self._delivery(f, q) < stop]
        if frames:
            self._delivered(frames, q)
        self.advance(stop)
        self.t_end = stop

    # -- main loop -----------------------------------------------------------------------
    def run(self) -> int:
        bus = self.bus
        tasks = self._tasks
        next_due = min([tk[0] for tk in tasks])
        next_flush = FLUSH_EVERY_NS
        # the quantum of a bus that grants only the quanta asked for (ima-canbus; not the
        # unit tests' in-process stand-in): 0, every quantum
        q = getattr(bus, "quantum_ns", 0) if self.skip_quanta else 0
        wall0 = time.perf_counter()
        try:
            while True:
                tick = bus.wait_tick()
                if tick is None:
                    self.stop_reason = proto.STOP_REASONS.get(bus.stopped, str(bus.stopped))
                    if q:
                        self._to_the_stop(q)
                    break
                T, t_until, frames = tick
                self._serving_t = T
                if frames:
                    if q:
                        self._delivered(frames, q)
                    else:
                        self._frames(frames)
                while next_due < t_until:
                    s = next_due
                    self.advance(s)
                    self.t_now = s
                    for tk in tasks:
                        if tk[0] == s:
                            tk[2](s)
                            tk[0] = tk[3]() if tk[1] == 0 else s + tk[1]
                    next_due = min([tk[0] for tk in tasks])
                self.advance(t_until)
                self.t_end = t_until
                if q and self._far_from_the_limits():
                    bus.done(t_until, min(next_due, t_until + SKIP_MAX_NS))
                else:
                    bus.done(t_until)
                if t_until >= next_flush:
                    # a run killed outright (kill -9) loses at most this much of the traces
                    self.events_f.flush()
                    self.truth_f.flush()
                    next_flush = t_until + FLUSH_EVERY_NS
                if self.interrupted:
                    # Ctrl-C (the launcher's SIGTERM): the quantum is flown and recorded, the
                    # bus ends the run for everyone, every trace complete up to here
                    self.stop_reason = "interrupted"
                    bus.stop()
                    break
        except Crash as c:
            t, reason = self.crash
            if t <= self._serving_t:  # in a quantum it was not granted (see SKIP_MAX_NS)
                self.event("world", "crash", t_ns=t, reason=reason,
                           found_late_ns=self._serving_t - t)
            else:
                self.event("world", "crash", t_ns=t, reason=reason)
            print(f"imaworld: crash at t={t / NS:.3f} s: {reason}; stopping the bus",
                  file=sys.stderr)
            self.t_end = t
            self.stop_reason = f"crash: {c}"
            bus.stop()
        except BusError:
            # The bus went away (ended by the launcher, or died): what was flown is recorded
            # all the same, then the error is told.
            self.stop_reason = "bus lost"
            self.t_now = max(self.t_now, self.t_end)
            self.finish(time.perf_counter() - wall0)
            raise
        self.t_now = max(self.t_now, self.t_end)
        self.finish(time.perf_counter() - wall0)
        return 0

    def _vote_summary(self) -> dict | None:
        sel = self.act.selector
        if not isinstance(sel, VotingSelector):
            return None
        vp = self.voting
        return {**sel.summary(), "thresholds": [_r(x, 6) for x in vp.thresholds],
                "persist": vp.persist, "offset_s": vp.offset_s,
                "period_ms": round(vp.period_s * 1000, 6)}

    def finish(self, wall_s: float) -> None:
        self._log_actuators()
        self.event("world", "stop", t_ns=self.t_end, reason=self.stop_reason)
        self.events_f.close()
        self.truth_f.close()
        final = self.truth()
        final["t_ns"] = self.t_now
        summary = {
            "aircraft": self.p.aircraft,
            "seed": self.opts.seed,
            "pilot": str(self.script.path),
            "turbulence": self.opts.turbulence,
            "wind_kt": _r(self.wind[0], 3), "wind_from_deg": _r(self.wind[1], 3),
            "terrain_ft": _r(self.opts.terrain_ft, 3),
            "trim": {k: _r(v, 6) for k, v in self.trim.items()},
            "crashed": self.crash is not None,
            "crash_t_s": None if self.crash is None else self.crash[0] / NS,
            "reason": self.crash[1] if self.crash else self.stop_reason,
            "t_end_ns": self.t_end,
            "steps": self.n,
            "final": final,
            "frames_sent": _named(self.sent),
            "frames_received": _named(self.received),
            "channels": self.opts.channels or 1,
            "vote": self._vote_summary(),
        }
        # only when used: a run without them writes the file it always wrote
        if self.faults is not None:
            summary["faults"] = self.faults.summary()
        if self.opts.test_switches:
            summary["test_switches"] = list(self.opts.test_switches)
        if self.pilot_model.events:
            summary["pilot_model"] = [{"t_ns": t, **f} for t, f in self.pilot_model.events]
        if self.ground.touchdown is not None:
            summary["landing"] = self.ground.summary()
        (self.run_dir / "world.json").write_text(json.dumps(summary, indent=1) + "\n")
        emu = self.t_end / NS
        print(f"imaworld: {emu:.1f} s emulated, {self.n} steps, {wall_s:.2f} s wall"
              + (f" ({emu / wall_s:.0f}x real time)" if wall_s > 0 else ""), file=sys.stderr)
