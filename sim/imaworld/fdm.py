# SPDX-License-Identifier: Apache-2.0
"""The JSBSim aircraft: set-up, trim, wind and turbulence, and fast access to its properties."""

from __future__ import annotations

import math
import os

import jsbsim

from ima.errors import ImaError

from .config import KT_TO_FPS, WorldParams


class TrimError(ImaError):
    pass


# Truth properties read through cached property nodes (much cheaper than fdm["name"]).
PROPS = {
    "lat": "position/lat-geod-deg",
    "lon": "position/long-gc-deg",
    "alt": "position/h-sl-ft",
    "agl": "position/h-agl-ft",
    "palt": "atmosphere/pressure-altitude",
    "cas": "velocities/vc-kts",
    "tas": "velocities/vtrue-kts",
    "vn": "velocities/v-north-fps",
    "ve": "velocities/v-east-fps",
    "hdot": "velocities/h-dot-fps",
    "phi": "attitude/phi-deg",
    "theta": "attitude/theta-deg",
    "psi": "attitude/psi-deg",
    "p": "velocities/p-rad_sec",
    "q": "velocities/q-rad_sec",
    "r": "velocities/r-rad_sec",
    "ax": "accelerations/n-pilot-x-norm",
    "ay": "accelerations/n-pilot-y-norm",
    "az": "accelerations/n-pilot-z-norm",
    "nz": "accelerations/Nz",
    "wind_n": "atmosphere/total-wind-north-fps",
    "wind_e": "atmosphere/total-wind-east-fps",
    "wow_l": "gear/unit[1]/WOW",  # weight on the main wheels
    "wow_r": "gear/unit[2]/WOW",
}
CONTROLS = ("fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm",
            "fcs/throttle-cmd-norm[0]")


class Aircraft:
    """One JSBSim FDM at `physics_hz`, trimmed straight and level at the start conditions.

    Controls are taken in the DBC convention (elevator + nose down, aileron + roll right,
    rudder + yaw right); JSBSim's c172p has the rudder the other way round (a positive
    fcs/rudder-cmd-norm yaws left), so the rudder is negated here and only here.
    """

    def __init__(self, params: WorldParams, start: dict, seed: int, terrain_ft: float,
                 wind: tuple[float, float] = (0.0, 270.0)) -> None:
        self.params = params
        fdm = jsbsim.FGFDMExec(None)
        fdm.set_debug_level(0)
        if not fdm.load_model(params.aircraft):
            raise ImaError(f"JSBSim cannot load the aircraft {params.aircraft!r}")
        fdm.set_dt(1.0 / params.physics_hz)
        # JSBSim's own generator (turbulence) is seeded from the run seed: same seed, same gusts.
        fdm["simulation/randomseed"] = seed & 0x7FFFFFFF
        fdm["ic/terrain-elevation-ft"] = terrain_ft
        fdm["ic/lat-geod-deg"] = start["lat_deg"]
        fdm["ic/long-gc-deg"] = start["lon_deg"]
        fdm["ic/h-sl-ft"] = start["altitude_ft"]
        fdm["ic/psi-true-deg"] = start["heading_deg"] % 360.0
        fdm["ic/gamma-deg"] = 0.0
        fdm["ic/vc-kts"] = start["airspeed_kt"]
        self.wind = wind
        if not fdm.run_ic():
            raise ImaError("JSBSim refused the initial conditions")
        fdm["propulsion/set-running"] = -1
        fdm["fcs/mixture-cmd-norm"] = params.mixture
        self.fdm = fdm
        pm = fdm.get_property_manager()
        self.node = {k: pm.get_node(v, False) for k, v in PROPS.items()}
        self.get = {k: n.get_double_value for k, n in self.node.items()}
        self.ctl_node = tuple(pm.get_node(n, False) for n in CONTROLS)
        self.ctl_set = tuple(n.set_double_value for n in self.ctl_node)
        self._steer = pm.get_node("fcs/steer-cmd-norm", False).set_double_value
        self._brakes = (pm.get_node("fcs/left-brake-cmd-norm", False).set_double_value,
                        pm.get_node("fcs/right-brake-cmd-norm", False).set_double_value)
        self._wind_n = pm.get_node("atmosphere/wind-north-fps", False)
        self._wind_e = pm.get_node("atmosphere/wind-east-fps", False)
        self.run = fdm.run

    def set_wind(self, speed_kt: float, from_deg: float) -> None:
        """Steady wind blowing from `from_deg` (true)."""
        a = math.radians(from_deg)
        self._wind_n.set_double_value(-speed_kt * KT_TO_FPS * math.cos(a))
        self._wind_e.set_double_value(-speed_kt * KT_TO_FPS * math.sin(a))

    def trim(self) -> dict:
        """Straight and level trim; returns the trimmed controls (DBC convention)."""
        fdm = self.fdm
        try:
            fdm["simulation/do_simple_trim"] = 1
        except Exception as e:  # jsbsim raises its own TrimFailureError/RuntimeError
            raise TrimError(f"JSBSim could not trim {self.params.aircraft} straight and level "
                            f"at the start conditions: {e}") from e
        if self.wind[0] > 0:
            self._restart_in_wind(*self.wind)
        return {
            "elev": fdm["fcs/elevator-cmd-norm"],
            "ail": fdm["fcs/aileron-cmd-norm"],
            "rud": -fdm["fcs/rudder-cmd-norm"],
            "thr": fdm["fcs/throttle-cmd-norm[0]"],
            "pitch_trim": fdm["fcs/pitch-trim-cmd-norm"],
            "theta_deg": fdm["attitude/theta-deg"],
        }

    def _restart_in_wind(self, speed_kt: float, from_deg: float) -> None:
        """Put the trimmed aircraft into the wind with the same air-relative state.

        JSBSim 1.3's trim does not hold a wind given with the initial conditions (it fails or
        comes out at the wrong airspeed), so we trim in calm air, then restart from the trimmed
        attitude with ground velocity = air velocity + wind (body axes, wings level) and the
        wind set last (JSBSim then keeps the ground velocity and derives the airspeed).
        """
        fdm = self.fdm
        th, ph, ps = (fdm["attitude/theta-rad"], fdm["attitude/phi-rad"],
                      fdm["attitude/psi-rad"])
        a = math.radians(from_deg)
        wn = -speed_kt * KT_TO_FPS * math.cos(a)
        we = -speed_kt * KT_TO_FPS * math.sin(a)
        along = wn * math.cos(ps) + we * math.sin(ps)
        u = fdm["velocities/u-fps"] + math.cos(th) * along
        v = fdm["velocities/v-fps"] - wn * math.sin(ps) + we * math.cos(ps)
        w = fdm["velocities/w-fps"] + math.sin(th) * along
        fdm["ic/h-sl-ft"] = fdm["position/h-sl-ft"]
        fdm["ic/theta-rad"] = th
        fdm["ic/phi-rad"] = ph
        fdm["ic/psi-true-rad"] = ps
        fdm["ic/u-fps"] = u
        fdm["ic/v-fps"] = v
        fdm["ic/w-fps"] = w
        fdm["ic/vw-mag-fps"] = speed_kt * KT_TO_FPS  # magnitude first, then direction
        fdm["ic/vw-dir-deg"] = (from_deg + 180.0) % 360.0  # where the wind blows to
        if not fdm.run_ic():
            raise ImaError("JSBSim refused the initial conditions in wind")

    def set_turbulence(self, severity: int, w20_kt: float) -> None:
        fdm = self.fdm
        if severity <= 0:
            fdm["atmosphere/turbulence/milspec/severity"] = 0
            return
        fdm["atmosphere/turb-type"] = 3  # Milspec (MIL-F-8785C, Dryden form)
        fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20_kt * KT_TO_FPS
        fdm["atmosphere/turbulence/milspec/severity"] = severity

    def set_controls(self, elev: float, ail: float, rud: float, thr: float) -> None:
        s = self.ctl_set
        s[0](elev)
        s[1](ail)
        s[2](-rud)
        s[3](thr)

    def set_ground_controls(self, rud: float, brake: float) -> None:
        """On the ground: the nose wheel steered with the rudder pedals (+ = right, as the
        DBC's rudder; JSBSim's fcs/steer-cmd-norm turns right when positive), and both main
        wheels braked."""
        self._steer(rud)
        self._brakes[0](brake)
        self._brakes[1](brake)


def quiet_stdout():
    """Point fd 1 at stderr (JSBSim writes its banner and messages to std::cout) and return a
    text stream on the original stdout, for the --status lines only."""
    import sys

    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    sys.stdout = os.fdopen(os.dup(2), "w", buffering=1)  # stray prints go to stderr too
    return os.fdopen(saved, "w", buffering=1)
