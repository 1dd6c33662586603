# SPDX-License-Identifier: Apache-2.0
"""Smart actuators: command selection over the redundancy channels (simplex, or the C voter's
mid-value select with monitoring), rate and position limits, hold-last and safe position when
commands stop."""

from __future__ import annotations

from collections import deque

from .config import NS, ActuatorParams
from .voter import Voter, mask_letters

NORMAL, HOLD_LAST, SAFE = 0, 1, 2
FOREVER = 1 << 62  # later than any instant of a run
STATE_NAMES = ("NORMAL", "HOLD_LAST", "SAFE")
CHANNELS = ("A", "B", "C")


class CommandSelector:
    """Where the redundancy-management voter plugs in (docs/redundancy.md).

    The actuators call `update()` for every ACT_CMD_x frame and `select()` once per physics
    step; `select()` returns (command, channel label) or (None, None) when no channel is fresh.
    A command is (elevator, aileron, rudder, throttle) in the DBC's sign convention.
    `newest_t()` is when the command path was last alive (hold-last counts from there),
    `commanded()` whether a command has ever been selectable. A selector whose
    `latches_safe` is true makes the safe position final once the actuators reach it after
    having been commanded.
    """

    latches_safe = False

    def __init__(self, n_channels: int = 3) -> None:
        self.last_t = [-1] * n_channels
        self.last_cmd: list[tuple | None] = [None] * n_channels

    def update(self, channel: int, t_ns: int, cmd: tuple) -> None:
        self.last_t[channel] = t_ns
        self.last_cmd[channel] = cmd

    def newest_t(self) -> int:
        return max(self.last_t)

    def commanded(self) -> bool:
        return self.newest_t() >= 0

    def select(self, now_ns: int, stale_ns: int) -> tuple[tuple | None, str | None]:
        raise NotImplementedError

    def holds_until(self, now_ns: int, stale_ns: int) -> int:
        """After select(now_ns): the first instant at which select() may answer otherwise, no
        command coming in meanwhile (an update() may change it at once)."""
        return now_ns + 1


class LowestLiveChannel(CommandSelector):
    """Use the lowest-lettered channel whose last command is fresh (simplex, before voting)."""

    def select(self, now_ns: int, stale_ns: int) -> tuple[tuple | None, str | None]:
        for ch, t in enumerate(self.last_t):
            if t >= 0 and now_ns - t <= stale_ns:
                return self.last_cmd[ch], CHANNELS[ch]
        return None, None

    def holds_until(self, now_ns: int, stale_ns: int) -> int:
        # the channel selected goes stale after stale_ns; a stale one comes back only with a
        # command
        for t in self.last_t:
            if t >= 0 and now_ns - t <= stale_ns:
                return t + stale_ns + 1
        return FOREVER


class VotingSelector(CommandSelector):
    """The smart actuators' voter (docs/redundancy.md): the C voter (nodes/include/voter/voter.h,
    through imaworld.voter) over channels A.. of the n configured, dim 4 (elev, ail, rud, thr).

    Voting frames come once per major frame, at `offset_ns` into it (k * period + offset). A
    channel is present in a vote when an ACT_CMD frame of it ended since the previous vote and
    by the vote (its newest such command is voted; frames that end later wait for the next
    vote). Voting starts with the first vote that has a command in it: until then the startup
    rule of the actuators holds, and no channel is counted absent. Between votes the last voted
    command is used; a vote without a candidate (SAFE, DISAGREE) gives (None, None), so the
    actuators hold the last voted command for stale + hold after the last vote that had one,
    then go to the safe position and stay there (`latches_safe`).

    `events` collects (t_ns, kind, fields) for the world's trace: "vote" when the status or
    the set of used channels changes, "voted_out" when a channel is declared failed.
    Frames of channels >= n are ignored.
    """

    latches_safe = True

    def __init__(self, n_channels: int, thresholds: tuple, persist: int, offset_ns: int,
                 period_ns: int, safe=(0.0, 0.0, 0.0, 0.0), never_vote_out: bool = False) -> None:
        if not 0 <= offset_ns < period_ns:
            raise ValueError(f"vote offset {offset_ns} ns is not within the {period_ns} ns frame")
        super().__init__(n_channels)
        self.n = n_channels
        # test switch no-vote-out: a channel the voter declares failed is taken back at once
        # and no voted_out is recorded (only to show that an oracle can fail)
        self.never_vote_out = never_vote_out
        self.voter = Voter(n_channels, 4, thresholds, persist, safe)
        self.period_ns = period_ns
        self.next_vote_t = offset_ns
        self._pending: list[deque] = [deque() for _ in range(n_channels)]
        self.started = False
        self.cmd: tuple | None = None
        self.label: str | None = None
        self.last_voted_t = -1  # the last vote that had a candidate
        self.status: str | None = None  # of the last vote
        self.used = ""  # letters of the channels the last vote used
        self.votes = 0
        self.events: list[tuple[int, str, dict]] = []
        self.voted_out: list[dict] = []  # {"t_ns", "node", "channel", "reason"}

    def update(self, channel: int, t_ns: int, cmd: tuple) -> None:
        if channel >= self.n:
            return
        super().update(channel, t_ns, cmd)
        self._pending[channel].append((t_ns, cmd))

    def newest_t(self) -> int:
        return self.last_voted_t

    def select(self, now_ns: int, stale_ns: int) -> tuple[tuple | None, str | None]:
        while self.next_vote_t <= now_ns:
            self._vote(self.next_vote_t)
            self.next_vote_t += self.period_ns
        return self.cmd, self.label

    def holds_until(self, now_ns: int, stale_ns: int) -> int:
        return self.next_vote_t

    def _vote(self, tv: int) -> None:
        values: list[tuple | None] = [None] * self.n
        for c, q in enumerate(self._pending):
            while q and q[0][0] <= tv:
                values[c] = q.popleft()[1]
        if not self.started:
            if all(v is None for v in values):
                return
            self.started = True
        r = self.voter.step(values)
        self.votes += 1
        used = mask_letters(r.used)
        if r.used:
            self.cmd, self.label, self.last_voted_t = r.value, used, tv
        else:
            self.cmd = self.label = None
        if r.status != self.status or used != self.used:
            self.status, self.used = r.status, used
            self.events.append((tv, "vote", {"status": r.status, "used": list(used)}))
        if r.newly_failed and self.never_vote_out:
            self.voter.forgive(r.newly_failed)
            return
        for c in range(self.n):
            if r.newly_failed >> c & 1:
                rec = {"node": f"node{c + 1}", "channel": CHANNELS[c],
                       "reason": self.voter.reason(c)}
                self.voted_out.append({"t_ns": tv, **rec})
                self.events.append((tv, "voted_out", rec))

    def summary(self) -> dict:
        """For world.json: the final vote and who was voted out."""
        return {"status": self.status, "used": list(self.used), "votes": self.votes,
                "disagree": self.voter.disagree, "voted_out": list(self.voted_out)}


def safe_position(p: ActuatorParams) -> tuple[float, float, float, float]:
    """Surfaces 0, throttle at its safe setting within its limits."""
    return (0.0, 0.0, 0.0, min(max(p.safe_throttle, p.throttle_min), p.throttle_max))


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
        self.safe_latched = False
        self.stale_ns = round(p.stale_s * NS)
        self.hold_ns = round(p.hold_s * NS)
        self.startup_ns = round(p.startup_hold_s * NS)
        lim = p.surface_limit
        self.lo = (-lim, -lim, -lim, p.throttle_min)
        self.hi = (lim, lim, lim, p.throttle_max)
        self.safe = safe_position(p)
        self.transitions: list[tuple[int, str, str | None]] = []  # (t_ns, state, channel)
        # Set by the fault injectors (faults.py): per actuator None, ("jam", position, 0) or
        # ("drive", position, rate): the actuator goes there at that rate, whatever the command.
        self.override: list | None = None
        self._moves: tuple = (None, ())  # (dt, each actuator's largest move in dt): step()
        # The target of the last _target() and until when it holds (targeted()); -1: to be
        # asked again (a command came in, or step() ran).
        self.target: tuple = self.trim
        self.until = -1

    def rate(self, i: int) -> float:
        """Actuator i's rate limit (normalised units per second)."""
        return self.p.throttle_rate if i == 3 else self.p.surface_rate

    def limit(self, i: int, side: int) -> float:
        """Actuator i's end stop on the side of `side`'s sign."""
        return self.hi[i] if side > 0 else self.lo[i]

    def neutral(self, i: int) -> float:
        """Where actuator i goes undriven: 0 (surfaces trail with the flow; throttle at idle)."""
        return min(max(0.0, self.lo[i]), self.hi[i])

    def command(self, channel: int, t_ns: int, cmd: tuple) -> None:
        """An ACT_CMD frame of redundancy channel `channel` (0 = A) that ended at t_ns."""
        self.selector.update(channel, t_ns, cmd)
        self.until = -1

    @property
    def ever_commanded(self) -> bool:
        return self.selector.commanded()

    def _target(self, now: int) -> tuple:
        sel = self.selector
        cmd, ch = sel.select(now, self.stale_ns)  # every step: a voter keeps voting
        if self.safe_latched:
            ch = None
            state, target = SAFE, self.safe
        elif cmd is not None:
            state, target = NORMAL, cmd
            self.last_cmd = cmd
        elif not sel.commanded():
            ch = None
            state, target = (HOLD_LAST, self.trim) if now <= self.startup_ns else (SAFE, self.safe)
        else:
            ch = None
            silent = now - sel.newest_t()
            if silent <= self.stale_ns + self.hold_ns:
                state, target = HOLD_LAST, self.last_cmd
            else:
                state, target = SAFE, self.safe
                self.safe_latched = sel.latches_safe
        if state != self.state or ch != self.channel:
            if state != self.state or ch is not None:
                self.transitions.append((now, STATE_NAMES[state], ch))
            self.state, self.channel = state, ch
        return target

    def targeted(self, now_ns: int) -> None:
        """The target at now_ns (`target`), and until when it holds (`until`) if no command
        comes in: what _target() would give at every instant from now_ns up to `until`, and
        the transitions it would record, are those it gives and records at now_ns."""
        self.target = self._target(now_ns)
        sel = self.selector
        if self.safe_latched or self.state == NORMAL:
            until = FOREVER
        elif not sel.commanded():
            until = self.startup_ns + 1 if now_ns <= self.startup_ns else FOREVER
        elif self.state == HOLD_LAST:
            until = sel.newest_t() + self.stale_ns + self.hold_ns + 1
        else:
            until = FOREVER
        self.until = max(min(until, sel.holds_until(now_ns, self.stale_ns)), now_ns + 1)

    def moves(self, dt_s: float) -> tuple:
        """The most each actuator moves in a step of dt_s: rate * dt (step() computes the same
        with an override)."""
        if self._moves[0] != dt_s:
            self._moves = (dt_s, tuple(self.rate(i) * dt_s for i in range(4)))
        return self._moves[1]

    def step(self, now_ns: int, dt_s: float) -> list[float]:
        """Move every actuator toward its target for one physics step starting at now_ns."""
        target = self._target(now_ns)
        self.until = -1
        pos, lo, hi = self.pos, self.lo, self.hi
        ov = self.override
        for i, m in enumerate(self.moves(dt_s)):
            tgt = target[i]
            if tgt < lo[i]:
                tgt = lo[i]
            elif tgt > hi[i]:
                tgt = hi[i]
            if ov is not None and ov[i] is not None:
                tgt, rate = ov[i][1], ov[i][2]  # a faulty actuator: the command does not count
                m = rate * dt_s
            d = tgt - pos[i]
            if d > m:
                d = m
            elif d < -m:
                d = -m
            pos[i] += d
        return pos
