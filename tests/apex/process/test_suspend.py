# SPDX-License-Identifier: Apache-2.0
"""SUSPEND (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_PARAM: no such process, or the caller itself (SUSPEND_SELF suspends that);
INVALID_MODE: the process is DORMANT or periodic; NO_ACTION: it is already suspended;
NO_ERROR: it is suspended (WAITING) until RESUME, even once what it waited for has happened.
"""

FRAMES = 1

CHECKS = {
    "suspend": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.dormant": "INVALID_MODE",
        "normal.self": "INVALID_PARAM",
        "normal.id_unknown": "INVALID_PARAM",
        "normal.dormant": "INVALID_MODE",
        "normal.periodic": "INVALID_MODE",
        "normal.ready": "NO_ERROR",
        "normal.ready.state": "WAITING",
        "normal.already": "NO_ACTION",
        "normal.timed_wait": "NO_ERROR",
        "normal.semaphore": "NO_ERROR",
        "normal.semaphore.given": 0,
        "normal.semaphore.no_waiter": 0,
        "normal.semaphore.state": "WAITING",
        "normal.ready.did_not_run": 0,
        "normal.timed_wait.did_not_run": 0,
        "normal.timed_wait.state": "WAITING",
        "normal.semaphore.did_not_run": 0,
        "normal.resumed.runs_at_once": "sleeper,ctl",
        "normal.semaphore.resumed": 1,
        "normal.semaphore.rc": "NO_ERROR",
        "normal.ready.resumed_ran": 1,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
