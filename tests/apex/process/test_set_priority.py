# SPDX-License-Identifier: Apache-2.0
"""SET_PRIORITY (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_PARAM: no such process, or PRIORITY outside MIN_PRIORITY_VALUE..MAX_PRIORITY_VALUE;
INVALID_MODE: the process is DORMANT; NO_ERROR: its current priority changes and it becomes
the newest process of that priority, with the rescheduling that follows.
"""

FRAMES = 1

CHECKS = {
    "set_priority": {
        "init.id_zero": "INVALID_PARAM",
        "init.priority_zero": "INVALID_PARAM",
        "init.dormant": "INVALID_MODE",
        "init.started": "NO_ERROR",
        "normal.priority_zero": "INVALID_PARAM",
        "normal.priority_240": "INVALID_PARAM",
        "normal.id_unknown": "INVALID_PARAM",
        "normal.dormant": "INVALID_MODE",
        "normal.raise_ready": "NO_ERROR",
        "normal.raise_ready.preempts": "a,ctl",
        "normal.stopped": "INVALID_MODE",
        "normal.same_priority": "NO_ERROR",
        "normal.lower_self": "NO_ERROR",
        # d then b (b became the newest of priority 5), e (4, ready before ctl became 4)
        "normal.lower_self.order": "d,b,e,ctl",
        "normal.current_priority": 4,
        "normal.base_priority": 10,
        "normal.waiting": "NO_ERROR",
        "normal.waiting.current_priority": 13,
        "normal.waiting.queue_order": "w2,w1,ctl",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
