# SPDX-License-Identifier: Apache-2.0
"""DELAYED_START (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_PARAM: no such process; DELAY_TIME out of range (negative, infinite, ending past the
end of the clock), or not below the PERIOD of a periodic process; NO_ACTION: the process is
not DORMANT; INVALID_CONFIG: its DEADLINE_TIME calculation is out of range; NO_ERROR: the
process is released after the delay (periodic: after the next period start plus the delay).
"""

FRAMES = 2

CHECKS = {
    "delayed_start": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.delay_negative": "INVALID_PARAM",
        "init.delay_infinite": "INVALID_PARAM",
        "init.periodic.delay_period": "INVALID_PARAM",
        "init.periodic.delay_above_period": "INVALID_PARAM",
        "init.aperiodic": "NO_ERROR",
        "init.aperiodic.state": "WAITING",
        "init.already_started": "NO_ACTION",
        "init.periodic": "NO_ERROR",
        "normal.self_running": "NO_ACTION",
        "normal.aperiodic": "NO_ERROR",
        "normal.aperiodic.state": "WAITING",
        "normal.aperiodic.deadline": 7_000_000,  # released at 2 ms, time capacity 5 ms
        "normal.zero": "NO_ERROR",
        "normal.zero.preempts": "zero,ctl",
        "normal.deadline_out_of_range": "INVALID_CONFIG",
        "normal.delay_beyond_clock": "INVALID_PARAM",
        "normal.periodic": "NO_ERROR",
        # NORMAL mode begins at 0 ms
        "init.aperiodic.released_at": 3_000_000,
        "init.periodic.released_at": 4_000_000,
        "init.periodic.next_release": 24_000_000,
        "normal.aperiodic.released_at": 2_000_000,
        "normal.periodic.released_at": 25_000_000,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
