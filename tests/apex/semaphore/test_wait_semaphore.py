# SPDX-License-Identifier: Apache-2.0
"""WAIT_SEMAPHORE (ARINC 653 Part 1, 3.7.2.3): every return code the standard lists.

INVALID_PARAM: no such semaphore, or TIME_OUT out of range (below -1, or ending past the end
of the clock); NO_ERROR: the value was above 0 and is decremented, or the caller waited and
was signalled; NOT_AVAILABLE: the value is 0 and TIME_OUT is 0; INVALID_MODE: the caller
would have to wait and may not (preemption locked, the error handler, here also the
initialisation process); TIMED_OUT: not signalled before the time-out.
"""

FRAMES = 1

CHECKS = {
    "wait_semaphore": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.timeout_minus_2": "INVALID_PARAM",
        "init.available": "NO_ERROR",
        "init.available.value": 1,
        "init.available.infinite": "NO_ERROR",
        "init.available.infinite.value": 0,
        "init.zero.no_wait": "NOT_AVAILABLE",
        "init.zero.would_wait": "INVALID_MODE",
        "init.zero.would_wait_forever": "INVALID_MODE",
        "normal.zero.no_wait": "NOT_AVAILABLE",
        "normal.zero.timed_out": "TIMED_OUT",
        "normal.zero.timed_out.elapsed": 2_000_000,
        "normal.timeout_beyond_clock": "INVALID_PARAM",
        "normal.preemption_locked": "INVALID_MODE",
        "normal.fifo.first": "READY",  # f_lo (5) waited first
        "normal.fifo.second": "WAITING",
        "normal.priority.first": "READY",  # p_hi (8) has the higher priority
        "normal.priority.second": "WAITING",
        "normal.zero.wait": "NO_ERROR",
        "normal.zero.wait.elapsed": 3_000_000,
        "normal.zero.wait.value": 0,  # the signal went to the waiting process
        "f_lo.rc": "NO_ERROR",
        "f_hi.rc": "NO_ERROR",
        "p_lo.rc": "NO_ERROR",
        "p_hi.rc": "NO_ERROR",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
