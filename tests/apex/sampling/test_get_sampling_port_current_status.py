# SPDX-License-Identifier: Apache-2.0
"""GET_SAMPLING_PORT_CURRENT_STATUS (ARINC 653 Part 2, sampling port extensions): every return
code the standard lists.

NO_ERROR with REFRESH_PERIOD, TIME_STAMP (when the latest message was written; 0 for an empty
port), MAX_MESSAGE_SIZE, PORT_DIRECTION, MESSAGE_AGE (FRESH within the refresh period, STALE
beyond it or when empty) and UPDATED (EMPTY_PORT, NEW_MESSAGE not read yet, CONSUMED_MESSAGE);
INVALID_PARAM: no such sampling port, the status left alone.
"""

FRAMES = 3
MS = 1_000_000


def _status(name: str, stamp: int, age: str, updated: str, direction: str = "DESTINATION") -> dict:
    return {
        name: "NO_ERROR",
        f"{name}.refresh_period": 25 * MS,
        f"{name}.time_stamp": stamp,
        f"{name}.max_message_size": 16,
        f"{name}.port_direction": direction,
        f"{name}.message_age": age,
        f"{name}.updated": updated,
    }


CHECKS = {
    "writer": {},
    "reader": {
        **_status("empty", 0, "STALE", "EMPTY_PORT"),
        "id_zero": "INVALID_PARAM",
        "id_zero.untouched": "yes",
        "id_unknown": "INVALID_PARAM",
        "id_unknown.untouched": "yes",
        **_status("new", 2 * MS, "FRESH", "NEW_MESSAGE"),
        **_status("read", 2 * MS, "FRESH", "CONSUMED_MESSAGE"),
        **_status("source.before_write", 0, "STALE", "EMPTY_PORT", "SOURCE"),
        **_status("source.written", 10 * MS, "FRESH", "NEW_MESSAGE", "SOURCE"),
        **_status("stale", 2 * MS, "STALE", "CONSUMED_MESSAGE"),
        **_status("new_again", 42 * MS, "FRESH", "NEW_MESSAGE"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
