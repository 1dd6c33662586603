# SPDX-License-Identifier: Apache-2.0
"""RECEIVE_BUFFER (ARINC 653 Part 1, 3.7.2.1): every return code the standard lists.

INVALID_PARAM: no such buffer, TIME_OUT out of range (below -1, or ending past the end of the
clock); NOT_AVAILABLE: the buffer is empty and TIME_OUT is 0;
INVALID_MODE: the caller would have to wait and may not (preemption locked, the error
handler, here also the initialisation process); TIMED_OUT: still empty when the time-out
expires; NO_ERROR: the oldest message and its LENGTH, at once or after waiting. When no
message is received (NOT_AVAILABLE, INVALID_MODE, TIMED_OUT) LENGTH is 0; on INVALID_PARAM it
is left alone (docs/apex-coverage.md, output parameters).
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def receive(prefix, rc, text="-", length=UNTOUCHED):
    return {prefix: rc, f"{prefix}.message": text, f"{prefix}.length": length}


def nothing(prefix, rc):
    """No message received: LENGTH 0, the buffer as it was."""
    return receive(prefix, rc, "(empty)", 0)


CHECKS = {
    "receive_buffer": {
        **receive("init.id_zero", "INVALID_PARAM"),
        **receive("init.id_unknown", "INVALID_PARAM"),
        **receive("init.timeout_minus_2", "INVALID_PARAM"),
        **nothing("init.empty.no_wait", "NOT_AVAILABLE"),
        **nothing("init.empty.would_wait", "INVALID_MODE"),
        **receive("init.message", "NO_ERROR", "m1", 2),
        **nothing("normal.empty.no_wait", "NOT_AVAILABLE"),
        **nothing("normal.empty.timed_out", "TIMED_OUT"),
        "normal.empty.timed_out.elapsed": 2_000_000,
        **receive("normal.timeout_beyond_clock", "INVALID_PARAM"),
        "normal.waiting_receivers": 2,
        # FIFO buffer: r1 waited first; PRIORITY buffer: q2 has the higher priority
        "r1.received": "f1",
        "r2.received": "f2",
        "q1.received": "p2",
        "q2.received": "p1",
        "normal.full.sender_waits": "WAITING",
        **receive("normal.full", "NO_ERROR", "a", 1),
        "normal.full.sender_released": "READY",
        **receive("normal.then.0", "NO_ERROR", "b", 1),
        **receive("normal.then.1", "NO_ERROR", "c", 1),
        **nothing("normal.preemption_locked", "INVALID_MODE"),
        "late_sender.sent": "NO_ERROR",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
