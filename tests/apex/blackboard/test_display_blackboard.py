# SPDX-License-Identifier: Apache-2.0
"""DISPLAY_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): every return code the standard lists.

INVALID_PARAM: no such blackboard, LENGTH above its maximum message size, LENGTH null or
negative; NO_ERROR: the message is displayed, replacing the previous one,
and every waiting reader gets it.
"""

FRAMES = 1

CHECKS = {
    "display_blackboard": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.length_over_max": "INVALID_PARAM",
        "init.length_zero": "INVALID_PARAM",
        "init.length_negative": "INVALID_PARAM",
        "init.errors.still_empty": "EMPTY",
        "init.first": "NO_ERROR",
        "init.first.read": "one/3",
        "init.first.occupied": "OCCUPIED",
        "init.largest": "NO_ERROR",
        "init.largest.read": "01234567/8",
        "init.replace": "NO_ERROR",
        "init.replace.read": "two/3",
        "normal.waiting_before": 3,
        "normal.to_waiting": "NO_ERROR",
        "normal.replaced": "NO_ERROR",
        "normal.waiting_after": 0,
        # the readers of priority 20 at once, in the order they waited; r_c (5) later, with
        # the message displayed when it was woken
        "normal.readers.order": "r_a:m1,r_b:m1,ctl,r_c:m1",
        "normal.replaced.read": "m2/2",
        "normal.no_reader": "NO_ERROR",
        "normal.no_reader.read": "m3/2",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
