# SPDX-License-Identifier: Apache-2.0
"""WAIT_EVENT (ARINC 653 Part 1, 3.7.2.4): every return code the standard lists.

INVALID_PARAM: no such event, or TIME_OUT out of range (below -1, or ending past the end of
the clock); NO_ERROR: the event is UP, or goes UP while the caller waits; NOT_AVAILABLE: it
is DOWN and TIME_OUT is 0; INVALID_MODE: the caller would have to wait and may not
(preemption locked, the error handler, here also the initialisation process); TIMED_OUT:
still DOWN when the time-out expires.
"""

FRAMES = 1


def wait(prefix, rc, elapsed=0):
    return {prefix: rc, f"{prefix}.elapsed": elapsed}


CHECKS = {
    "wait_event": {
        **wait("init.id_zero", "INVALID_PARAM"),
        **wait("init.id_unknown", "INVALID_PARAM"),
        **wait("init.timeout_minus_2", "INVALID_PARAM"),
        **wait("init.down.no_wait", "NOT_AVAILABLE"),
        **wait("init.down.would_wait", "INVALID_MODE"),
        **wait("init.down.would_wait_forever", "INVALID_MODE"),
        **wait("init.up", "NO_ERROR"),
        **wait("init.up.infinite", "NO_ERROR"),
        **wait("normal.down.no_wait", "NOT_AVAILABLE"),
        **wait("normal.down.timed_out", "TIMED_OUT", 2_000_000),
        **wait("normal.timeout_beyond_clock", "INVALID_PARAM"),
        **wait("normal.preemption_locked", "INVALID_MODE"),
        **wait("normal.down.wait", "NO_ERROR", 3_000_000),
        **wait("normal.up", "NO_ERROR"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
