# SPDX-License-Identifier: Apache-2.0
"""CLEAR_QUEUING_PORT (ARINC 653 Part 1, 3.6.2.2): every return code the standard lists.

NO_ERROR: the messages waiting in the destination port are discarded (and an overflow that
lost messages before the clear is not reported by the next receive); INVALID_PARAM: no such
queuing port; INVALID_MODE: the port is not a destination.
"""

FRAMES = 3

CHECKS = {
    "src": {},
    "dst": {
        "init.empty": "NO_ERROR",
        "id_zero": "INVALID_PARAM",
        "id_unknown": "INVALID_PARAM",
        "source_port": "INVALID_MODE",
        "before.nb_message": 3,
        "clear": "NO_ERROR",
        "clear.nb_message": 0,
        "clear.receive": "NOT_AVAILABLE",
        "clear.receive.message": "(empty)",
        "clear.again": "NO_ERROR",
        "overflowed": "NO_ERROR",
        "overflowed.nb_message": 0,
        "later": "NO_ERROR",
        "later.message": "D",
        "later.overflow_forgotten": "NO_ERROR",
        "later.overflow_forgotten.message": "G",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_the_overflow_happened_before_the_clear(apex):
    apex.assert_ran()
    overflows = apex.of_kind("port", event="overflow")
    assert [(e["t_ns"], e["port"]) for e in overflows] == [(24_000_000, "QP_SMALL")] * 2
