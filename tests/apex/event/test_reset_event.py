# SPDX-License-Identifier: Apache-2.0
"""RESET_EVENT (ARINC 653 Part 1, 3.7.2.4): every return code the standard lists.

INVALID_PARAM: no such event; NO_ERROR: the event is DOWN, and waiting processes go on
waiting.
"""

FRAMES = 1

CHECKS = {
    "reset_event": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.down": "NO_ERROR",
        "init.down.state": "DOWN",
        "init.up": "NO_ERROR",
        "init.up.state": "DOWN",
        "init.up.wait": "NOT_AVAILABLE",
        "normal.waiter": "NO_ERROR",
        "normal.waiter.state": "WAITING",
        "waiter.rc": "NO_ERROR",
        "normal.set.waiter": "DORMANT",
        "normal.up": "NO_ERROR",
        "normal.up.state": "DOWN",
        "normal.up.wait": "NOT_AVAILABLE",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
