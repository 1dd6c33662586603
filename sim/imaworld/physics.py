# SPDX-License-Identifier: Apache-2.0
"""The world's physics steps (World's part): the actuators and JSBSim stepped up to an instant,
in C++ (stepper.py) or in Python, each step judged for a crash, the wheels near the ground,
and the actuators' events logged in time order."""

from __future__ import annotations

import math

from . import stepper
from .config import NS
from .landing import Ground

NEAR_GROUND_FT = 15.0  # below this height (of the centre of gravity) the wheels are watched


class Crash(Exception):
    pass


class Physics:
    """World's physics steps; the World holds the state they use (ac, act, ground, p, hz, dt,
    n, next_step_t, t_now, _stepper) and provides event()."""

    def advance(self, t: int) -> None:
        """Run every physics step ending at or before t (the state is then at the last t_n <= t)."""
        if self.next_step_t > t:
            return
        st = self._stepper
        if st is None or self.act.override is not None:
            self._advance_in_python(t)
        else:
            # the steps in C++ (stepper.py), each the same as one of _advance_in_python's; back
            # here for a new actuator target, or to judge a step near a limit or the ground
            act, ground, hz = self.act, self.ground, self.hz
            n = self.n
            while True:
                code = st.run(t, n, act.pos, act.target, act.until, ground.touchdown is not None)
                m = st.n
                if m != n:
                    n = self.n = m
                    self.next_step_t = (n + 1) * NS // hz
                    self.t_now = n * NS // hz
                if code == stepper.DONE:
                    break
                if code == stepper.TARGET:
                    act.targeted(n * NS // hz)
                else:
                    self._judge(act.pos)
        self._log_actuators()

    def _advance_in_python(self, t: int) -> None:
        step, set_controls, run = self.act.step, self.ac.set_controls, self.ac.run
        dt, hz = self.dt, self.hz
        n = self.n
        while self.next_step_t <= t:
            pos = step(n * NS // hz, dt)
            set_controls(pos[0], pos[1], pos[2], pos[3])
            run()
            n += 1
            self.next_step_t = (n + 1) * NS // hz
            self.n = n
            self.t_now = n * NS // hz
            self._judge(pos)

    def _judge(self, pos) -> None:
        """After a step: a crash ends the run; near the ground, the wheels."""
        g, lim = self.ac.get, self.p.limits
        max_roll = lim.max_roll_deg
        a, r = g["agl"](), g["phi"]()
        if not a > 0.0 or not -max_roll <= r <= max_roll:
            if a != a or r != r:
                self._crash("state is not a number")
            self._crash("ground contact" if a <= 0.0 else f"roll {r:.1f} deg")
        c, z = g["cas"](), g["nz"]()
        # the load factor counts in the air: on the wheels the gear's springs give spikes
        if not c <= lim.max_cas_kt or not (abs(z) <= lim.max_load_g
                                           or (self.ground.touchdown is not None
                                               and a < NEAR_GROUND_FT)):
            self._crash(f"airspeed {c:.1f} kt" if not c <= lim.max_cas_kt
                        else f"load factor {z:.1f} g")
        if a < NEAR_GROUND_FT:
            self._near_ground(self.ground, a, r, pos, self.dt)

    def _near_ground(self, ground: Ground, agl_ft: float, roll_deg: float, pos, dt: float) -> None:
        """The wheels near the ground: steering, brakes, touchdown, bounces, the stop."""
        g = self.ac.get
        self.ac.set_ground_controls(pos[2], ground.brake_step(self.t_now, dt))
        vn, ve = g["vn"](), g["ve"]()
        why = ground.step(self.t_now, g["wow_l"]() > 0.5 or g["wow_r"]() > 0.5, agl_ft,
                          -g["hdot"](), roll_deg, g["theta"](),
                          math.hypot(vn, ve) / 1.6878098571011957, g["lat"](), g["lon"]())
        for t, kind, f in ground.events[self._ground_ev_done:]:
            self.event("gear", kind, t_ns=t, **f)
        self._ground_ev_done = len(ground.events)
        if why is not None:
            self._crash(why)

    def _log_actuators(self) -> None:
        """Actuator state changes and the voter's events, in time order (a vote before the
        state change it causes)."""
        act = self.act
        votes = getattr(act.selector, "events", ())
        if len(act.transitions) == self._act_trans_done and len(votes) == self._vote_ev_done:
            return
        out = [(t, 0, i, kind, f) for i, (t, kind, f) in
               enumerate(votes[self._vote_ev_done:])]
        out += [(t, 1, i, "actuator_state", {"state": state, "channel": ch}) for i, (t, state, ch)
                in enumerate(act.transitions[self._act_trans_done:])]
        out.sort(key=lambda e: e[:3])
        for t, _, _, kind, f in out:
            self.event("actuators", kind, t_ns=t, **f)
        self._act_trans_done = len(act.transitions)
        self._vote_ev_done = len(votes)

    def _crash(self, reason: str) -> None:
        self.crash = (self.t_now, reason)
        raise Crash(reason)
