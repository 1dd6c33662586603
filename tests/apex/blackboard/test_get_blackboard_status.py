# SPDX-License-Identifier: Apache-2.0
"""GET_BLACKBOARD_STATUS (ARINC 653 Part 1, 3.7.2.2): every return code the standard lists.

NO_ERROR with EMPTY_INDICATOR, MAX_MESSAGE_SIZE and WAITING_PROCESSES; INVALID_PARAM: no
such blackboard.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "get_blackboard_status": {
        "init.empty": "EMPTY",
        "init.max_message_size": 100,
        "init.waiting": 0,
        "init.displayed": "OCCUPIED",
        "init.cleared": "EMPTY",
        "init.id_zero": "INVALID_PARAM",
        "init.id_zero.untouched": UNTOUCHED,
        "init.id_negative": "INVALID_PARAM",
        "init.id_negative.untouched": UNTOUCHED,
        "init.id_unknown": "INVALID_PARAM",
        "init.id_unknown.untouched": UNTOUCHED,
        "normal.empty": "EMPTY",
        "normal.waiting": 2,
        "normal.displayed": "OCCUPIED",
        "normal.displayed.waiting": 0,
        "normal.id_unknown": "INVALID_PARAM",
        "normal.id_unknown.untouched": UNTOUCHED,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
