# SPDX-License-Identifier: Apache-2.0
"""CREATE_SAMPLING_PORT (ARINC 653 Part 1, 3.6.2.1): every return code the standard lists.

INVALID_CONFIG: no sampling port of that name in the configuration, or MAX_MESSAGE_SIZE,
PORT_DIRECTION or REFRESH_PERIOD out of range or not as configured; NO_ACTION: already
created; INVALID_MODE: NORMAL mode. Output parameters are written only on NO_ERROR.
"""

FRAMES = 1


def _refused(name: str, code: str) -> dict:
    return {name: code, f"{name}.id_untouched": 0x5A5A5A5A}


CHECKS = {
    "creator": {
        **_refused("unknown_name", "INVALID_CONFIG"),
        **_refused("queuing_port_name", "INVALID_CONFIG"),
        **_refused("size_smaller", "INVALID_CONFIG"),
        **_refused("size_larger", "INVALID_CONFIG"),
        **_refused("size_zero", "INVALID_CONFIG"),
        **_refused("size_negative", "INVALID_CONFIG"),
        **_refused("direction_differs", "INVALID_CONFIG"),
        **_refused("direction_invalid", "INVALID_CONFIG"),
        **_refused("refresh_differs", "INVALID_CONFIG"),
        **_refused("refresh_negative", "INVALID_CONFIG"),
        **_refused("refresh_infinite", "INVALID_CONFIG"),
        "source": "NO_ERROR",
        "source.id_written": "yes",
        "destination": "NO_ERROR",
        "destination.id_written": "yes",
        "ids_distinct": "yes",
        **_refused("already_created", "NO_ACTION"),
        **_refused("already_created.destination", "NO_ACTION"),
        "source.usable": "NO_ERROR",
        **_refused("normal.create", "INVALID_MODE"),
        "normal.create.not_created": "INVALID_CONFIG",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
