# SPDX-License-Identifier: Apache-2.0
"""Constants and helpers shared by the world tests (importable; conftest.py is not)."""

from __future__ import annotations

from pathlib import Path

from ima.canbus.codec import MESSAGES

ROOT = Path(__file__).resolve().parents[2]
PILOTS = ROOT / "sim" / "pilots"
NS = 1_000_000_000
ACT_A = MESSAGES["ACT_CMD_A"]
ACT_CMDS = tuple(MESSAGES[f"ACT_CMD_{c}"] for c in "ABC")  # redundancy channels A, B, C


def model_voting():
    """The voting of the shipped triplex model (the world has none of its own)."""
    from imaworld.config import VotingParams

    from ima.deploy import load_system

    system = load_system(ROOT / "config" / "systems" / "rpas_triplex.yaml")
    v = system.voting
    return VotingParams(tuple(v["thresholds"][a] for a in ("elev", "ail", "rud", "thr")),
                        v["persist"], v["offset_s"], system.major_frame_s)


def act_cmd_injector(cmd_of_t, channel_msg=ACT_A, until_ns: int | None = None):
    """ACT_CMD frames at 20 Hz: cmd_of_t(t_ns) -> (elev, ail, rud, thr) or None for silence."""
    cnt = [0]

    def inj(t_from, t_until):
        if t_from % 50_000_000 or (until_ns is not None and t_from >= until_ns):
            return []
        cmd = cmd_of_t(t_from)
        if cmd is None:
            return []
        cnt[0] = (cnt[0] + 1) & 0xF
        return [(t_from, channel_msg.frame_id, channel_msg.encode(*cmd, cnt[0]))]

    return inj
