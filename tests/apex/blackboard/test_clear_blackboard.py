# SPDX-License-Identifier: Apache-2.0
"""CLEAR_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): every return code the standard lists.

INVALID_PARAM: no such blackboard; NO_ERROR: the blackboard is EMPTY, readers find nothing
and waiting readers go on waiting.
"""

FRAMES = 1

CHECKS = {
    "clear_blackboard": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.empty": "NO_ERROR",
        "init.empty.indicator": "EMPTY",
        "init.displayed.indicator": "OCCUPIED",
        "init.occupied": "NO_ERROR",
        "init.occupied.indicator": "EMPTY",
        "init.occupied.read": "NOT_AVAILABLE",
        "normal.reader_waiting": "NO_ERROR",
        "normal.reader_waiting.state": "WAITING",
        "reader.got": "after",
        "normal.displayed.reader": "DORMANT",
        "normal.occupied": "NO_ERROR",
        "normal.occupied.read": "NOT_AVAILABLE",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
