# SPDX-License-Identifier: Apache-2.0
"""RESUME (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_PARAM: no such process, or the caller itself; INVALID_MODE: the process is DORMANT
or periodic; NO_ACTION: it is not suspended; NO_ERROR: it is no longer suspended, ready at
once (preempting a lower-priority caller) unless it still waits for something else.
"""

FRAMES = 1

CHECKS = {
    "resume": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.dormant": "INVALID_MODE",
        "normal.self": "INVALID_PARAM",
        "normal.id_unknown": "INVALID_PARAM",
        "normal.dormant": "INVALID_MODE",
        "normal.periodic": "INVALID_MODE",
        "normal.not_suspended": "NO_ACTION",
        "normal.waiting_not_suspended": "NO_ACTION",
        "normal.suspended": "NO_ERROR",
        "high.suspend_self": "NO_ERROR",
        "normal.suspended.preempts": "high,ctl",
        "normal.suspended_while_waiting": "NO_ERROR",
        "normal.suspended_while_waiting.state": "WAITING",
        "normal.resumed_already": "NO_ACTION",
        "normal.lower_priority": "NO_ERROR",
        "normal.lower_priority.runs_later": "ctl,idle",
        "normal.suspended_while_waiting.woke_at": 5_000_000,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
