# SPDX-License-Identifier: Apache-2.0
"""Smart actuators: command selection over the redundancy channels, rate and position limits,
hold-last and safe position when commands stop."""

from __future__ import annotations

from .config import NS, ActuatorParams

NORMAL, HOLD_LAST, SAFE = 0, 1, 2
STATE_NAMES = ("NORMAL", "HOLD_LAST", "SAFE")
CHANNELS = ("A", "B", "C")


class CommandSelector:
    """Where the redundancy-management voter plugs in (DESIGN.md §3).

    The actuators call `update()` for every ACT_CMD_x frame and `select()` once per physics
    step; `select()` returns (command, channel label) or (None, None) when no channel is fresh.
    A command is (elevator, aileron, rudder, throttle) in the DBC's sign convention.
    """

    def __init__(self, n_channels: int = 3) -> None:
        self.last_t = [-1] * n_channels
        self.last_cmd: list[tuple | None] = [None] * n_channels

    def update(self, channel: int, t_ns: int, cmd: tuple) -> None:
        self.last_t[channel] = t_ns
        self.last_cmd[channel] = cmd

    def newest_t(self) -> int:
        return max(self.last_t)

    def select(self, now_ns: int, stale_ns: int) -> tuple[tuple | None, str | None]:
        raise NotImplementedError


class LowestLiveChannel(CommandSelector):
    """Use the lowest-lettered channel whose last command is fresh (simplex, before voting)."""

    def select(self, now_ns: int, stale_ns: int) -> tuple[tuple | None, str | None]:
        for ch, t in enumerate(self.last_t):
            if t >= 0 and now_ns - t <= stale_ns:
                return self.last_cmd[ch], CHANNELS[ch]
        return None, None


class Actuators:
    """Four smart actuators sharing one command path. Positions are in the DBC convention:
    elevator + = nose down, aileron + = roll right, rudder + = yaw right, throttle 0..1."""

    def __init__(self, p: ActuatorParams, trim: tuple[float, float, float, float],
                 selector: CommandSelector | None = None) -> None:
        self.p = p
        self.selector = selector or LowestLiveChannel()
        self.pos = list(trim)
        self.trim = tuple(trim)
        self.last_cmd: tuple = tuple(trim)  # what hold-last holds
        self.state = HOLD_LAST  # holding the trimmed positions until the first command
        self.channel: str | None = None
        self.ever_commanded = False
        self.stale_ns = round(p.stale_s * NS)
        self.hold_ns = round(p.hold_s * NS)
        self.startup_ns = round(p.startup_hold_s * NS)
        lim = p.surface_limit
        self.lo = (-lim, -lim, -lim, p.throttle_min)
        self.hi = (lim, lim, lim, p.throttle_max)
        self.safe = (0.0, 0.0, 0.0, min(max(p.safe_throttle, p.throttle_min), p.throttle_max))
        self.transitions: list[tuple[int, str, str | None]] = []  # (t_ns, state, channel)

    def command(self, channel: int, t_ns: int, cmd: tuple) -> None:
        """An ACT_CMD frame of redundancy channel `channel` (0 = A) that ended at t_ns."""
        self.selector.update(channel, t_ns, cmd)
        self.ever_commanded = True

    def _target(self, now: int) -> tuple:
        cmd, ch = self.selector.select(now, self.stale_ns)
        if cmd is not None:
            state, target = NORMAL, cmd
            self.last_cmd = cmd
        elif not self.ever_commanded:
            ch = None
            state, target = (HOLD_LAST, self.trim) if now <= self.startup_ns else (SAFE, self.safe)
        else:
            ch = None
            silent = now - self.selector.newest_t()
            if silent <= self.stale_ns + self.hold_ns:
                state, target = HOLD_LAST, self.last_cmd
            else:
                state, target = SAFE, self.safe
        if state != self.state or ch != self.channel:
            if state != self.state or ch is not None:
                self.transitions.append((now, STATE_NAMES[state], ch))
            self.state, self.channel = state, ch
        return target

    def step(self, now_ns: int, dt_s: float) -> list[float]:
        """Move every actuator toward its target for one physics step starting at now_ns."""
        target = self._target(now_ns)
        p = self.p
        pos, lo, hi = self.pos, self.lo, self.hi
        for i in range(4):
            tgt = target[i]
            if tgt < lo[i]:
                tgt = lo[i]
            elif tgt > hi[i]:
                tgt = hi[i]
            d = tgt - pos[i]
            m = (p.throttle_rate if i == 3 else p.surface_rate) * dt_s
            if d > m:
                d = m
            elif d < -m:
                d = -m
            pos[i] += d
        return pos
