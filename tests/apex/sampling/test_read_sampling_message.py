# SPDX-License-Identifier: Apache-2.0
"""READ_SAMPLING_MESSAGE (ARINC 653 Part 1, 3.6.2.1): every return code the standard lists.

NO_ERROR with VALIDITY = VALID while the message's age is within the refresh period, INVALID
once it is older; NO_ACTION: the port is empty; INVALID_PARAM: no such sampling port;
INVALID_MODE: the port is not a destination. NO_ACTION sets LENGTH to 0 and VALIDITY to
INVALID (the message buffer is left alone); the errors leave every output alone.
"""

FRAMES = 3


def _read(name: str, validity: str, message: str) -> dict:
    return {
        f"{name}.rc": "NO_ERROR",
        f"{name}.validity": validity,
        f"{name}.length": 5,
        f"{name}.message": message,
    }


def _refused(name: str, code: str, written: str = "none") -> dict:
    return {name: code, f"{name}.outputs_written": written}


CHECKS = {
    "writer": {},
    "reader": {
        **_read("fresh", "VALID", "msg0"),
        **_refused("never_written", "NO_ACTION", "LENGTH=0,VALIDITY=INVALID,"),
        **_refused("id_zero", "INVALID_PARAM"),
        **_refused("id_unknown", "INVALID_PARAM"),
        **_refused("source_port", "INVALID_MODE"),
        **_read("stale", "INVALID", "msg0"),
        **_read("fresh_again", "VALID", "msg2"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_validity_changes_are_in_the_trace(apex):
    apex.assert_ran()
    changes = [
        (e["t_ns"], e["event"]) for e in apex.of_kind("port", partition="reader", port="SP_IN")
    ]
    assert changes == [(10_000_000, "valid"), (30_000_000, "invalid"), (50_000_000, "valid")]
