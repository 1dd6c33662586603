# SPDX-License-Identifier: Apache-2.0
"""TIMED_WAIT (ARINC 653 Part 1, 3.4.2): every return code the standard lists.

NO_ERROR (the delay is seen in GET_TIME; 0 yields to the ready processes of the same
priority), INVALID_PARAM (delay out of range: negative, infinite, or beyond the end of the
clock), INVALID_MODE (a caller that may not wait: here the initialisation process).
"""

FRAMES = 2

CHECKS = {
    "delay": {
        "init.invalid_mode": "INVALID_MODE",
        "delay.rc": "NO_ERROR",
        "delay.elapsed": 3_000_000,
        "delay.others_ran": 1,
        "negative": "INVALID_PARAM",
        "negative.elapsed": 0,
        "infinite": "INVALID_PARAM",
        "infinite.elapsed": 0,
        "past_window_end.rc": "NO_ERROR",
        "past_window_end.time": 20_000_000,
        "beyond_clock": "INVALID_PARAM",
        "beyond_clock.elapsed": 0,
    },
    "yield": {
        "yield.order": "A1,B1,A2,B2,A3,C1,C2",
        "yield.errors": 0,
        "yield.elapsed": 0,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
