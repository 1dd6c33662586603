# SPDX-License-Identifier: Apache-2.0
"""GET_SEMAPHORE_STATUS (ARINC 653 Part 1, 3.7.2.3): every return code the standard lists.

NO_ERROR with CURRENT_VALUE, MAXIMUM_VALUE and WAITING_PROCESSES; INVALID_PARAM: no such
semaphore.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "get_semaphore_status": {
        "init.current_value": 2,
        "init.maximum_value": 4,
        "init.waiting": 0,
        "init.other.current_value": 7,
        "init.other.maximum_value": 9,
        "init.taken.current_value": 0,
        "init.id_zero": "INVALID_PARAM",
        "init.id_zero.untouched": UNTOUCHED,
        "init.id_negative": "INVALID_PARAM",
        "init.id_negative.untouched": UNTOUCHED,
        "init.id_unknown": "INVALID_PARAM",
        "init.id_unknown.untouched": UNTOUCHED,
        "normal.current_value": 0,
        "normal.waiting": 3,
        "normal.signalled.waiting": 2,
        "normal.id_unknown": "INVALID_PARAM",
        "normal.id_unknown.untouched": UNTOUCHED,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
