# SPDX-License-Identifier: Apache-2.0
"""CREATE_QUEUING_PORT (ARINC 653 Part 1, 3.6.2.2): every return code the standard lists.

INVALID_CONFIG: no queuing port of that name in the configuration, or MAX_MESSAGE_SIZE,
MAX_NB_MESSAGE or PORT_DIRECTION out of range or not as configured; INVALID_PARAM: invalid
QUEUING_DISCIPLINE; NO_ACTION: already created; INVALID_MODE: NORMAL mode. Output parameters
are written only on NO_ERROR.
"""

FRAMES = 1


def _refused(name: str, code: str) -> dict:
    return {name: code, f"{name}.id_untouched": 0x5A5A5A5A}


CHECKS = {
    "creator": {
        **_refused("unknown_name", "INVALID_CONFIG"),
        **_refused("sampling_port_name", "INVALID_CONFIG"),
        **_refused("size_smaller", "INVALID_CONFIG"),
        **_refused("size_larger", "INVALID_CONFIG"),
        **_refused("size_zero", "INVALID_CONFIG"),
        **_refused("size_negative", "INVALID_CONFIG"),
        **_refused("nb_message_smaller", "INVALID_CONFIG"),
        **_refused("nb_message_larger", "INVALID_CONFIG"),
        **_refused("nb_message_zero", "INVALID_CONFIG"),
        **_refused("nb_message_negative", "INVALID_CONFIG"),
        **_refused("direction_differs", "INVALID_CONFIG"),
        **_refused("direction_invalid", "INVALID_CONFIG"),
        **_refused("discipline_invalid", "INVALID_PARAM"),
        **_refused("discipline_negative", "INVALID_PARAM"),
        "source_fifo": "NO_ERROR",
        "source_fifo.id_written": "yes",
        "destination_priority": "NO_ERROR",
        "destination_priority.id_written": "yes",
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
