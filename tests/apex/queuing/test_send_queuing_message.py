# SPDX-License-Identifier: Apache-2.0
"""SEND_QUEUING_MESSAGE (ARINC 653 Part 1, 3.6.2.2): every return code the standard lists.

INVALID_PARAM: no such queuing port, LENGTH null or negative, TIME_OUT out of range (below
-1 or beyond the end of the clock);
INVALID_CONFIG: LENGTH above the maximum message size; INVALID_MODE: the port is not a
source, or the caller would have to wait and may not (the initialisation process);
NOT_AVAILABLE: the queue is full and TIME_OUT is 0; TIMED_OUT: still full when the time-out
expires; NO_ERROR: sent, at once or after waiting for room.
"""

FRAMES = 2

CHECKS = {
    "sender": {
        "id_zero": "INVALID_PARAM",
        "id_unknown": "INVALID_PARAM",
        "sampling_port_id": "INVALID_PARAM",
        "length_zero": "INVALID_PARAM",
        "length_negative": "INVALID_PARAM",
        "length_over_max": "INVALID_CONFIG",
        "timeout_minus_2": "INVALID_PARAM",
        "destination_port": "INVALID_MODE",
        **{f"send.{k}": "NO_ERROR" for k in range(4)},
        "full.no_wait": "NOT_AVAILABLE",
        "full.would_wait": "INVALID_MODE",
        "full.would_wait_forever": "INVALID_MODE",
        "normal.full.no_wait": "NOT_AVAILABLE",
        "normal.full.timed_out": "TIMED_OUT",
        "normal.full.timed_out.elapsed": 2_000_000,
        "normal.timeout_minus_2": "INVALID_PARAM",
        "normal.timeout_beyond_clock": "INVALID_PARAM",
        "normal.timeout_beyond_clock.elapsed": 0,
        "normal.waiting_processes": 1,
        "normal.nb_message": 4,
        "normal.full.wait": "NO_ERROR",
        "normal.full.wait.sent_at": 20_000_000,
        "normal.space": "NO_ERROR",
    },
    "receiver": {
        "frame0.received": "m0/16,m1/3,m2/16,m3/16",
        "frame0.then": "NOT_AVAILABLE",
        "frame1.received": "m4/16,m5/16",
        "frame1.then": "NOT_AVAILABLE",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_nothing_overflows(apex):
    apex.assert_ran()
    assert apex.of_kind("port", event="overflow") == []
    channel = apex.run.stats["channels"][0]
    assert (channel["messages"], channel["overflows"]) == (6, 0)
