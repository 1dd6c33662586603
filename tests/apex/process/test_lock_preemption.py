# SPDX-License-Identifier: Apache-2.0
"""LOCK_PREEMPTION (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

NO_ACTION: the partition is not in NORMAL mode (or the caller is the error handler);
INVALID_CONFIG: LOCK_LEVEL is already MAX_LOCK_LEVEL; NO_ERROR: the level grows by one and
is returned. While it is above 0 no other process is scheduled and services that would wait
return INVALID_MODE.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "lock_preemption": {
        "init.no_action": "NO_ACTION",
        "init.no_action.untouched": UNTOUCHED,
        "init.partition_status": 0,
        "normal.lock": "NO_ERROR",
        "normal.lock.level": 1,
        "normal.lock.partition_status": 1,
        "normal.start_higher": "NO_ERROR",
        "normal.start_higher.not_run": "",
        "normal.timed_wait": "INVALID_MODE",
        "normal.timed_wait_zero": "INVALID_MODE",
        "normal.suspend_self": "INVALID_MODE",
        "normal.wait_semaphore": "INVALID_MODE",
        "normal.wait_semaphore_no_wait": "NOT_AVAILABLE",
        "normal.receive_buffer": "INVALID_MODE",
        "normal.read_blackboard": "INVALID_MODE",
        "normal.wait_event": "INVALID_MODE",
        "normal.no_time_passed": 0,
        "normal.nested.level": 16,
        "normal.max_lock_level": "INVALID_CONFIG",
        "normal.max_lock_level.untouched": UNTOUCHED,
        "normal.level_1.not_run": "",
        "normal.unlocked.order": "high,low",
        "normal.unlocked.partition_status": 0,
        "periodic.periodic_wait": "INVALID_MODE",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
