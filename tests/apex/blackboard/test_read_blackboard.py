# SPDX-License-Identifier: Apache-2.0
"""READ_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): every return code the standard lists.

INVALID_PARAM: no such blackboard, TIME_OUT out of range (below -1, or ending past the end of
the clock); NOT_AVAILABLE: the blackboard is empty and TIME_OUT
is 0; INVALID_MODE: the caller would have to wait and may not (preemption locked, the error
handler, here also the initialisation process); TIMED_OUT: still empty when the time-out
expires; NO_ERROR: the displayed message and its LENGTH, at once or when it is displayed.
LENGTH is set to 0 when no message is read (NOT_AVAILABLE, INVALID_MODE, TIMED_OUT) and left
alone on INVALID_PARAM (docs/apex-coverage.md, output parameters).
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def read(prefix, rc, text="-", length=UNTOUCHED):
    return {prefix: rc, f"{prefix}.message": text, f"{prefix}.length": length}


def nothing(prefix, rc):
    """No message read: LENGTH 0, the buffer as it was."""
    return read(prefix, rc, "(empty)", 0)


CHECKS = {
    "read_blackboard": {
        **read("init.id_zero", "INVALID_PARAM"),
        **read("init.id_unknown", "INVALID_PARAM"),
        **read("init.timeout_minus_2", "INVALID_PARAM"),
        **nothing("init.empty.no_wait", "NOT_AVAILABLE"),
        **nothing("init.empty.would_wait", "INVALID_MODE"),
        **nothing("init.empty.would_wait_forever", "INVALID_MODE"),
        **read("init.occupied", "NO_ERROR", "hello", 5),
        **read("init.occupied.again", "NO_ERROR", "hello", 5),
        **read("normal.occupied", "NO_ERROR", "hello", 5),
        **nothing("normal.empty.no_wait", "NOT_AVAILABLE"),
        **nothing("normal.empty.timed_out", "TIMED_OUT"),
        "normal.empty.timed_out.elapsed": 2_000_000,
        **read("normal.timeout_beyond_clock", "INVALID_PARAM"),
        **nothing("normal.preemption_locked", "INVALID_MODE"),
        **read("normal.preemption_locked.occupied", "NO_ERROR", "hello", 5),
        **read("normal.empty.wait", "NO_ERROR", "late", 4),
        "normal.empty.wait.elapsed": 3_000_000,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
