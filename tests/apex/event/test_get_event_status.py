# SPDX-License-Identifier: Apache-2.0
"""GET_EVENT_STATUS (ARINC 653 Part 1, 3.7.2.4): every return code the standard lists.

NO_ERROR with EVENT_STATE and WAITING_PROCESSES; INVALID_PARAM: no such event.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "get_event_status": {
        "init.state": "DOWN",
        "init.waiting": 0,
        "init.set.state": "UP",
        "init.set.other_unchanged": "DOWN",
        "init.id_zero": "INVALID_PARAM",
        "init.id_zero.untouched": UNTOUCHED,
        "init.id_negative": "INVALID_PARAM",
        "init.id_negative.untouched": UNTOUCHED,
        "init.id_unknown": "INVALID_PARAM",
        "init.id_unknown.untouched": UNTOUCHED,
        "normal.state": "DOWN",
        "normal.waiting": 2,
        "normal.set.state": "UP",
        "normal.set.waiting": 0,
        "normal.id_unknown": "INVALID_PARAM",
        "normal.id_unknown.untouched": UNTOUCHED,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
