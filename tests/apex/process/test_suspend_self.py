# SPDX-License-Identifier: Apache-2.0
"""SUSPEND_SELF (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_MODE: preemption is locked, the caller is the error handler (or here the
initialisation process), or a periodic process; INVALID_PARAM: TIME_OUT out of range (below
-1, or ending past the end of the clock); NO_ERROR: TIME_OUT 0 (no wait), or resumed by
another process before the time-out; TIMED_OUT: the time-out expired.
"""

FRAMES = 1

CHECKS = {
    "suspend_self": {
        "init.invalid_mode": "INVALID_MODE",
        "init.zero.invalid_mode": "INVALID_MODE",
        "normal.zero": "NO_ERROR",
        "normal.zero.elapsed": 0,
        "normal.timeout_minus_2": "INVALID_PARAM",
        "normal.timeout_minus_2.elapsed": 0,
        "normal.timed_out": "TIMED_OUT",
        "normal.timed_out.elapsed": 2_000_000,
        "normal.timeout_beyond_clock": "INVALID_PARAM",
        "normal.timeout_beyond_clock.elapsed": 0,
        "normal.preemption_locked": "INVALID_MODE",
        "normal.preemption_locked.elapsed": 0,
        "normal.resumed": "NO_ERROR",
        "normal.resumed.elapsed": 3_000_000,  # suspended at 2 ms, resumed at 5 ms
        "normal.resumed_before_time_out": "NO_ERROR",
        "normal.resumed_before_time_out.elapsed": 1_000_000,
        "normal.waiting_seen": 2,
        "resumer.resume": "NO_ERROR",
        "resumer.resume_before_time_out": "NO_ERROR",
        "periodic.invalid_mode": "INVALID_MODE",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
