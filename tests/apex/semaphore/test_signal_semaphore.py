# SPDX-License-Identifier: Apache-2.0
"""SIGNAL_SEMAPHORE (ARINC 653 Part 1, 3.7.2.3): every return code the standard lists.

INVALID_PARAM: no such semaphore; NO_ACTION: the value is already MAXIMUM_VALUE; NO_ERROR:
the value grows by one, or the first waiting process gets the unit (and runs at once if its
priority is higher than the caller's).
"""

FRAMES = 1

CHECKS = {
    "signal_semaphore": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.first": "NO_ERROR",
        "init.first.value": 1,
        "init.second": "NO_ERROR",
        "init.second.value": 2,
        "init.at_maximum": "NO_ACTION",
        "init.at_maximum.value": 2,
        "init.maximum_zero": "NO_ACTION",
        "normal.waiting": 2,
        "normal.to_higher": "NO_ERROR",
        "normal.to_lower": "NO_ERROR",
        "normal.to_waiting.value": 0,
        "normal.to_waiting.waiting": 0,
        "normal.order": "hi,ctl,ctl2,lo",
        "normal.no_waiter": "NO_ERROR",
        "normal.no_waiter.value": 1,
        "normal.id_unknown": "INVALID_PARAM",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
