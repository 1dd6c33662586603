# SPDX-License-Identifier: Apache-2.0
"""SEND_BUFFER (ARINC 653 Part 1, 3.7.2.1): every return code the standard lists.

INVALID_PARAM: no such buffer, LENGTH above its maximum message size, LENGTH null or
negative, TIME_OUT out of range (below -1, or ending past the end of the
clock); NOT_AVAILABLE: the buffer is full and TIME_OUT is 0; INVALID_MODE: the caller would
have to wait and may not (preemption locked, the error handler, here also the initialisation
process); TIMED_OUT: still full when the time-out expires; NO_ERROR: the message is in the
buffer, or handed to a waiting receiver, at once or after waiting for room.
"""

FRAMES = 1

CHECKS = {
    "send_buffer": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.length_over_max": "INVALID_PARAM",
        "init.length_zero": "INVALID_PARAM",
        "init.length_negative": "INVALID_PARAM",
        "init.timeout_minus_2": "INVALID_PARAM",
        "init.send.0": "NO_ERROR",
        "init.send.1": "NO_ERROR",
        "init.full.no_wait": "NOT_AVAILABLE",
        "init.full.would_wait": "INVALID_MODE",
        "init.full.would_wait_forever": "INVALID_MODE",
        "init.send.bp": "NO_ERROR",
        "normal.full.no_wait": "NOT_AVAILABLE",
        "normal.full.timed_out": "TIMED_OUT",
        "normal.full.timed_out.elapsed": 2_000_000,
        "normal.full.nb_message": 2,
        "normal.full.waiting_processes": 2,
        "normal.timeout_beyond_clock": "INVALID_PARAM",
        # FIFO buffer: s1 (priority 5) waited before s2 (priority 6)
        "normal.fifo.order": "i0,i1,s1,s2",
        # PRIORITY buffer: p_hi (8) is served before p_lo (7), which waited longer
        "normal.priority.order": "p0,ph,pl",
        "normal.to_waiting_receiver": "NO_ERROR",
        "normal.to_waiting_receiver.preempts": "recv_hi:hand,ctl",
        "normal.to_waiting_receiver.not_queued": 0,
        "normal.space": "NO_ERROR",
        "normal.space.infinite": "NO_ERROR",
        "normal.preemption_locked": "INVALID_MODE",
        "normal.full.wait": "NO_ERROR",
        "normal.full.wait.order": "b,c",
        "s1.sent": "NO_ERROR",
        "s2.sent": "NO_ERROR",
        "p_lo.sent": "NO_ERROR",
        "p_hi.sent": "NO_ERROR",
        "rx_late.received": "a",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
