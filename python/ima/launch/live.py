# SPDX-License-Identifier: Apache-2.0
"""The live status of a launched system: follows the run's traces as they grow (each node's
partition modes, HM events, membership and monitor reports; the actuators' vote) and renders
them with the aircraft state and a progress bar (rich)."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

from ima.launch.summary import MEMBERSHIP_PREFIX, MONITOR_PREFIX, parse_members


class Follower:
    """Reads the complete lines appended to a JSON-lines file since the last call."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.offset = 0
        self.partial = b""

    def new_records(self) -> list[dict]:
        try:
            with open(self.path, "rb") as f:
                f.seek(self.offset)
                data = f.read()
        except OSError:
            return []
        self.offset += len(data)
        data = self.partial + data
        lines = data.split(b"\n")
        self.partial = lines.pop()
        out = []
        for line in lines:
            try:
                rec = json.loads(line)
            except ValueError:
                continue
            if isinstance(rec, dict):
                out.append(rec)
        return out


@dataclass
class NodeView:
    name: str
    modes: dict[str, str] = field(default_factory=dict)  # partition -> mode
    hm_events: int = 0
    last_hm: str = ""
    members: list[str] = field(default_factory=list)
    monitor: str = ""
    killed: bool = False
    hung: bool = False


class LiveState:
    """What the status view shows, updated from the traces (at most every `period_s`)."""

    def __init__(self, run_dir: Path, nodes: list[str], kills: dict[str, float],
                 period_s: float = 0.25, hangs: dict[str, float] | None = None) -> None:
        self.nodes = {n: NodeView(n, members=list(nodes)) for n in nodes}
        self.kills = kills
        self.hangs = hangs or {}
        self.period_s = period_s
        self._last = 0.0
        self._followers = {n: Follower(run_dir / f"{n}.jsonl") for n in nodes}
        self._world = Follower(run_dir / "world.jsonl")
        self.vote_status = "-"
        self.vote_used = "-"
        self.voted_out: list[str] = []
        self.status: dict = {}

    def update(self, status: dict) -> None:
        self.status = status
        now = time.monotonic()
        if now - self._last < self.period_s:
            return
        self._last = now
        t = float(status.get("t_s", 0.0))
        for name, fol in self._followers.items():
            view = self.nodes[name]
            if name in self.kills and t >= self.kills[name]:
                view.killed = True
            if name in self.hangs and t >= self.hangs[name]:
                view.hung = True
            for rec in fol.new_records():
                kind = rec.get("kind")
                if kind == "mode" and rec.get("partition"):
                    view.modes[rec["partition"]] = rec.get("mode", "?")
                elif kind == "hm":
                    view.hm_events += 1
                    view.last_hm = f"{rec.get('partition')}: {rec.get('error')} → {rec.get('action')}"
                elif kind == "app_message":
                    text = rec.get("text", "")
                    if text.startswith(MEMBERSHIP_PREFIX):
                        view.members = parse_members(text)
                    elif text.startswith(MONITOR_PREFIX):
                        view.monitor = text[len(MONITOR_PREFIX):]
        for rec in self._world.new_records():
            if rec.get("kind") == "vote":
                self.vote_status = str(rec.get("status", "-"))
                used = rec.get("used")
                self.vote_used = ",".join(used) if isinstance(used, list) else str(used)
            elif rec.get("kind") == "voted_out":
                self.voted_out.append(f"{rec.get('node')}@{rec['t_ns'] / 1e9:.2f}s ({rec.get('reason')})")

    def render(self):
        from rich.table import Table

        st = self.status
        t = Table(title=(f"t={st.get('t_s', 0):7.1f} s   {st.get('mode') or '-':>10}   "
                         f"{st.get('alt_ft', 0):6.0f} ft   {st.get('airspeed_kt', 0):5.1f} kt   "
                         f"{st.get('heading_deg', 0):5.1f}°   vote {self.vote_status} "
                         f"[{self.vote_used}]"),
                  expand=False)
        for col in ("node", "partitions", "HM events", "membership", "monitor"):
            t.add_column(col)
        for view in self.nodes.values():
            if view.killed or view.hung:
                t.add_row(view.name, "[red]stopped[/]" if view.killed else "[red]hung[/]",
                          str(view.hm_events), "-", "-")
                continue
            parts = " ".join(f"{p}:{m}" for p, m in sorted(view.modes.items())) or "starting"
            hm = str(view.hm_events) + (f" ({view.last_hm})" if view.last_hm else "")
            t.add_row(view.name, parts, hm, ",".join(view.members), view.monitor or "ok")
        if self.voted_out:
            t.caption = "voted out: " + "; ".join(self.voted_out)
        return t
