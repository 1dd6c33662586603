# SPDX-License-Identifier: Apache-2.0
"""SET_EVENT (ARINC 653 Part 1, 3.7.2.4): every return code the standard lists.

INVALID_PARAM: no such event; NO_ERROR: the event is UP (already UP included) and every
process waiting on it is released.
"""

FRAMES = 1

CHECKS = {
    "set_event": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.down": "NO_ERROR",
        "init.down.state": "UP",
        "init.up": "NO_ERROR",
        "init.up.state": "UP",
        "normal.waiting_before": 3,
        "normal.waiters": "NO_ERROR",
        "w_a.rc": "NO_ERROR",
        "w_b.rc": "NO_ERROR",
        "w_c.rc": "NO_ERROR",  # released before its time-out, which then never fires
        "normal.waiters.state": "UP",
        "normal.waiting_after": 0,
        "normal.order": "w_a,w_b,ctl,w_c",
        "normal.stays_up": "NO_ERROR",
        "normal.id_unknown": "INVALID_PARAM",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
