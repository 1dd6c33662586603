# SPDX-License-Identifier: Apache-2.0
"""STOP (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_PARAM: no such process, or the calling process itself (STOP_SELF stops that);
NO_ACTION: the process is DORMANT; NO_ERROR: the process becomes DORMANT wherever it was
(ready, waiting on a delay, a semaphore or its next period, suspended, STARTed before
NORMAL mode), leaves its queues, and START restarts it from its entry point.
"""

FRAMES = 2

CHECKS = {
    "stop": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.dormant": "NO_ACTION",
        "init.started": "NO_ERROR",
        "init.started.state": "DORMANT",
        "normal.self": "INVALID_PARAM",
        "normal.ready": "NO_ERROR",
        "normal.ready.state": "DORMANT",
        "normal.dormant": "NO_ACTION",
        "normal.semaphore.waiting_before": 1,
        "normal.waiting_semaphore": "NO_ERROR",
        "normal.semaphore.waiting_after": 0,
        # nobody waits any more: the signal is kept in the semaphore
        "normal.semaphore.value_after_signal": 1,
        "normal.timed_wait": "NO_ERROR",
        "normal.timed_wait.state": "DORMANT",
        "normal.periodic_wait": "NO_ERROR",
        "normal.suspended": "NO_ERROR",
        "normal.suspended.restart": "NO_ERROR",
        "normal.restart": "NO_ERROR",
        "normal.timed_wait.never_woke": 0,
        "normal.semaphore.never_got": 0,
        "normal.restart.ran": "ready",
        "normal.suspended.restart.ran": 1,
        "normal.periodic_wait.no_release": 1,
        "pending.never_ran": 0,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_stops_are_in_the_trace(apex):
    apex.assert_ran()
    stops = [e["name"] for e in apex.of_kind("process", event="stop")]
    for name in ("pending", "ready", "sem", "delay", "cyclic", "susp"):
        assert name in stops, stops
