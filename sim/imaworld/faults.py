# SPDX-License-Identifier: Apache-2.0
"""The world's fault injectors: the classes `python -m imaworld --fault SPEC` accepts, their
parameters, and the manager that starts and ends their spells and sets what each one does on
the sensors, the smart actuators and the remote pilot station.

Each fault is active over the spells of its spec (faultspec.py). At the first instant of a
spell the manager captures what the fault freezes (a surface's position, the AHRS's last
output, the pitot's total pressure), writes a `fault` event `applied`, and the targets behave
faulty from that instant on; at the spell's end it writes `cleared` and they behave normally
again. Faults on one target combine in the order they were applied (the latest applied of
two that replace a value wins).
"""

from __future__ import annotations

from dataclasses import dataclass

from .config import FaultParams
from .faultspec import NEVER, FaultSpec, FaultSpecError, param_float

AHRS_AXES = ("roll", "pitch", "hdg", "p", "q", "r")  # index in the AHRS's value vector
SURFACES = ("elev", "ail", "rud", "thr")  # index in the actuators' position vector


@dataclass(frozen=True)
class FaultClass:
    src: str  # the world.jsonl `src` of its events: "sensors", "actuators", "station"
    target: str | None  # fixed target, or None: the `surface` parameter names it
    params: tuple  # the KEY=VALUE parameters it takes
    doc: str


CLASSES = {
    "gps_loss": FaultClass("sensors", "gps", (), "the receiver reports no fix (fix 0, 2 "
                           "satellites, zero data, counter running), as the script's gps: lost"),
    "gps_frozen": FaultClass("sensors", "gps", (), "the receiver repeats its last frames byte "
                             "for byte, counter included"),
    "gps_jump": FaultClass("sensors", "gps", ("north_m", "east_m"), "the reported position is "
                           "offset by north_m, east_m (metres)"),
    "ahrs_bias": FaultClass("sensors", "ahrs", ("axis", "value"), "value (deg or deg/s) added "
                            "to one AHRS output: axis=roll|pitch|hdg|p|q|r"),
    "ahrs_stuck": FaultClass("sensors", "ahrs", ("counter",), "every AHRS value repeats its "
                             "last output before the spell; counter=run (default: the frames "
                             "keep coming, valid, counters running) or frozen (the last frames "
                             "repeat byte for byte)"),
    "pitot_blocked": FaultClass("sensors", "air_data", (), "pitot and its drain blocked, static "
                                "port open: the total pressure is trapped, so the IAS follows "
                                "altitude (rises in a climb, falls in a descent)"),
    "c2_loss": FaultClass("station", "c2_link", (), "the C2 link goes down both ways: no "
                          "uplink sent, no downlink heard"),
    "ap_disengage": FaultClass("station", "pilot_mode", (), "the station commands DIRECT over "
                               "the uplink (an autopilot disengagement)"),
    "actuator_jam": FaultClass("actuators", None, ("surface",), "the actuator stays where it "
                               "was at the spell's start"),
    "actuator_hardover": FaultClass("actuators", None, ("surface", "value"), "the actuator runs "
                                    "to its limit on the side of value's sign at its rate"),
    "actuator_float": FaultClass("actuators", None, ("surface", "rate"), "the actuator is no "
                                 "longer driven: it drifts to 0 (surfaces: the aerodynamic "
                                 "neutral; throttle: idle) at rate per second"),
}


def describe() -> str:
    """One line per class, for --help."""
    return "; ".join(f"{k}({','.join(c.params)})" if c.params else k for k, c in CLASSES.items())


def _check(spec: FaultSpec, fp: FaultParams) -> dict:
    """The class's parameters of a spec, checked: {"target", "detail"}; FaultSpecError if bad."""
    where = f"{spec.cls}:fid={spec.fid}"
    c = CLASSES.get(spec.cls)
    if c is None:
        raise FaultSpecError(f"{where}: not a fault class of the world (it injects "
                             f"{', '.join(CLASSES)})")
    extra = [k for k in spec.params if k not in c.params]
    if extra:
        takes = f"it takes {', '.join(c.params)}" if c.params else "it takes no parameter"
        raise FaultSpecError(f"{where}: unknown parameter '{extra[0]}' ({takes})")
    p = spec.params
    detail: dict = {}
    target = c.target
    if "surface" in c.params:
        target = p.get("surface")
        if target not in SURFACES:
            raise FaultSpecError(f"{where}: surface={target or ''} must be one of "
                                 f"{'|'.join(SURFACES)}")
    if spec.cls == "gps_jump":
        n, e = param_float(spec, "north_m", 0.0), param_float(spec, "east_m", 0.0)
        if "north_m" not in p and "east_m" not in p:
            raise FaultSpecError(f"{where}: give north_m=METRES and/or east_m=METRES")
        detail = {"north_m": n, "east_m": e}
    elif spec.cls == "ahrs_bias":
        if p.get("axis") not in AHRS_AXES:
            raise FaultSpecError(f"{where}: axis={p.get('axis', '')} must be one of "
                                 f"{'|'.join(AHRS_AXES)}")
        if "value" not in p:
            raise FaultSpecError(f"{where}: value=NUMBER is required (deg, or deg/s for p, q, r)")
        detail = {"axis": p["axis"], "value": param_float(spec, "value")}
    elif spec.cls == "ahrs_stuck":
        counter = p.get("counter", "run")
        if counter not in ("run", "frozen"):
            raise FaultSpecError(f"{where}: counter={counter} must be run or frozen")
        detail = {"counter": counter}
    elif spec.cls == "actuator_hardover":
        v = param_float(spec, "value")
        if v is None or v == 0:
            raise FaultSpecError(f"{where}: value=NUMBER, not 0, is required (its sign says "
                                 "which limit)")
        detail = {"side": 1 if v > 0 else -1}
    elif spec.cls == "actuator_float":
        rate = param_float(spec, "rate", fp.float_rate_per_s)
        if not rate > 0:
            raise FaultSpecError(f"{where}: rate must be positive (normalised units per second)")
        detail = {"rate": rate}
    return {"target": target, "detail": detail}


def check_all(specs: list[FaultSpec], fp: FaultParams) -> None:
    """Every spec is a world fault with good parameters, and fault ids are unique."""
    seen = set()
    for s in specs:
        _check(s, fp)
        if s.fid in seen:
            raise FaultSpecError(f"fid={s.fid} is given to two faults; each needs its own")
        seen.add(s.fid)


@dataclass
class _Fault:
    spec: FaultSpec
    cls: FaultClass
    target: str
    detail: dict  # the checked parameters
    next_t: int
    spell: int = -1  # the active spell, -1: not active
    order: int = 0  # when it was applied (combination order)
    captured: object = None  # what the spell froze


class WorldFaults:
    """Starts and ends the faults' spells on the world's parts. `world` gives the parts (gps,
    ahrs, adc, act, ac.get) and `event()`; `due(t)` runs every start or end at instant t."""

    def __init__(self, specs: list[FaultSpec], world, fp: FaultParams) -> None:
        self.w = world
        self.fp = fp
        self.faults: list[_Fault] = []
        for s in specs:
            chk = _check(s, fp)
            self.faults.append(_Fault(s, CLASSES[s.cls], chk["target"], chk["detail"],
                                      s.next_change(-1)))
        self._applied = 0
        # station effects, read by the world
        self.c2_down = False
        self.disengage = False
        self.pitot_pt: float | None = None

    def next_t(self) -> int:
        t = min((f.next_t for f in self.faults), default=NEVER)
        return t if t < NEVER else 1 << 62

    def due(self, t: int) -> None:
        changed = False
        for f in self.faults:  # command-line order at one instant
            if f.next_t > t:
                continue
            k = f.spec.spell(t)
            if f.spell >= 0 and k != f.spell:
                self._clear(f, t)
                changed = True
            if k >= 0 and k != f.spell:
                self._apply(f, k, t)
                changed = True
            f.next_t = f.spec.next_change(t)
        if changed:
            self._effects()

    # -- one fault ----------------------------------------------------------------------
    def _event(self, f: _Fault, t: int, state: str, detail: dict) -> None:
        self.w.event(f.cls.src, "fault", t_ns=t, fid=f.spec.fid, **{"class": f.spec.cls},
                     target=f.target, state=state, detail=detail)

    def _apply(self, f: _Fault, k: int, t: int) -> None:
        w, cls = self.w, f.spec.cls
        f.spell = k
        self._applied += 1
        f.order = self._applied
        detail = dict(f.detail)
        if f.spec.duration == "intermittent":
            detail["spell"] = k
        if cls == "actuator_jam":
            i = SURFACES.index(f.target)
            f.captured = w.act.pos[i]
            detail["position"] = round(f.captured, 6)
        elif cls == "actuator_hardover":
            i = SURFACES.index(f.target)
            f.captured = w.act.limit(i, f.detail["side"])
            detail["to"] = f.captured
        elif cls == "ahrs_stuck":
            # the last output before the spell; none yet: the spell's first sample (Ahrs)
            f.captured = [w.ahrs.last_vals, w.ahrs.last_frames or None]
            if w.ahrs.last_vals is not None:
                roll, pitch, hdg = w.ahrs.last_vals[:3]
                detail.update(roll_deg=round(roll, 3), pitch_deg=round(pitch, 3),
                              hdg_deg=round(hdg, 3))
        elif cls == "pitot_blocked":
            from .sensors import impact_pressure, static_pressure

            g = w.ac.get
            ias = g["cas"]()
            f.captured = static_pressure(g["palt"]()) + impact_pressure(ias)
            detail["ias_kt"] = round(ias, 3)
        self._event(f, t, "applied", detail)

    def _clear(self, f: _Fault, t: int) -> None:
        detail = {"spell": f.spell} if f.spec.duration == "intermittent" else {}
        f.spell = -1
        f.captured = None
        self._event(f, t, "cleared", detail)

    # -- what the active faults do ----------------------------------------------------------
    def _effects(self) -> None:
        """Sets every part's fault state from the active faults, in the order applied."""
        w = self.w
        gps_state = None
        gps_off = None
        ahrs_ops: list = []
        pitot = None
        c2_down = disengage = False
        override: list = [None] * 4
        for f in sorted((f for f in self.faults if f.spell >= 0), key=lambda f: f.order):
            cls, d = f.spec.cls, f.detail
            if cls == "gps_loss":
                gps_state = "lost"
            elif cls == "gps_frozen":
                gps_state = "frozen"
            elif cls == "gps_jump":
                n, e = gps_off or (0.0, 0.0)
                gps_off = (n + d["north_m"], e + d["east_m"])
            elif cls == "ahrs_bias":
                ahrs_ops.append(("bias", AHRS_AXES.index(d["axis"]), d["value"]))
            elif cls == "ahrs_stuck":
                ahrs_ops.append(("stuck", f.captured, d["counter"] == "frozen"))
            elif cls == "pitot_blocked":
                pitot = f.captured
            elif cls == "c2_loss":
                c2_down = True
            elif cls == "ap_disengage":
                disengage = True
            else:
                i = SURFACES.index(f.target)
                if cls == "actuator_jam":
                    override[i] = ("jam", f.captured, 0.0)
                elif cls == "actuator_hardover":
                    override[i] = ("drive", f.captured, w.act.rate(i))
                else:
                    override[i] = ("drive", w.act.neutral(i), d["rate"])
        w.gps.fault_state = gps_state
        w.gps.offset = gps_off
        w.ahrs.fault_ops = ahrs_ops or None
        self.pitot_pt = pitot
        self.c2_down = c2_down
        self.disengage = disengage
        w.act.override = override if any(o is not None for o in override) else None

    def summary(self) -> list[dict]:
        """For world.json: each fault as given."""
        return [{"fid": f.spec.fid, "class": f.spec.cls, "target": f.target,
                 "duration": f.spec.duration, "spec": f.spec.text} for f in self.faults]
