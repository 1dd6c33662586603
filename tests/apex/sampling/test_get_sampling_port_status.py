# SPDX-License-Identifier: Apache-2.0
"""GET_SAMPLING_PORT_STATUS (ARINC 653 Part 1, 3.6.2.1): NO_ERROR with the configured values
and LAST_MSG_VALIDITY, INVALID_PARAM for an unknown identifier (output untouched)."""

FRAMES = 2
UNTOUCHED = 0x5A5A5A5A


def _status(direction: str) -> dict:
    return {
        "status.rc": "NO_ERROR",
        "status.refresh_period": 25_000_000,
        "status.max_message_size": 24,
        "status.port_direction": direction,
        "id_zero": "INVALID_PARAM",
        "id_zero.untouched": UNTOUCHED,
        "id_unknown": "INVALID_PARAM",
        "id_unknown.untouched": UNTOUCHED,
    }


CHECKS = {
    "writer": _status("SOURCE"),
    "reader": {
        **_status("DESTINATION"),
        "after_valid_read.last_msg_validity": "VALID",
        "after_invalid_read.last_msg_validity": "INVALID",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
