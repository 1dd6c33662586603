# SPDX-License-Identifier: Apache-2.0
"""UNLOCK_PREEMPTION (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

NO_ACTION: the partition is not in NORMAL mode, preemption is not locked (or the caller is
the error handler); NO_ERROR: the level drops by one and is returned; at 0 the scheduler
runs the highest-priority ready process.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "unlock_preemption": {
        "init.no_action": "NO_ACTION",
        "init.no_action.level": UNTOUCHED,
        "normal.not_locked": "NO_ACTION",
        "normal.not_locked.level": UNTOUCHED,
        "normal.nested": "NO_ERROR",
        "normal.nested.level": 1,
        "normal.last": "NO_ERROR",
        "normal.last.level": 0,
        "normal.last.order": "p1,high,mid,p0",
        "normal.last.partition_status": 0,
        "normal.stop_self_unlocks": 0,
        "normal.after_stop_self": "NO_ACTION",
        "normal.after_stop_self.level": UNTOUCHED,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
