# SPDX-License-Identifier: Apache-2.0
"""WRITE_SAMPLING_MESSAGE (ARINC 653 Part 1, 3.6.2.1): every return code the standard lists.

INVALID_PARAM: no such sampling port, or LENGTH null or negative; INVALID_CONFIG: LENGTH above
the port's maximum message size; INVALID_MODE: the port is not a source; NO_ERROR otherwise.
The reader in the next window sees the last successful write, never a refused one.
"""

FRAMES = 2

CHECKS = {
    "writer": {
        "length_max": "NO_ERROR",
        "write": "NO_ERROR",
        "id_zero": "INVALID_PARAM",
        "id_unknown": "INVALID_PARAM",
        "queuing_port_id": "INVALID_PARAM",
        "length_zero": "INVALID_PARAM",
        "length_negative": "INVALID_PARAM",
        "length_over_max": "INVALID_CONFIG",
        "destination_port": "INVALID_MODE",
        "normal.write": "NO_ERROR",
        "normal.length_over_max": "INVALID_CONFIG",
        "normal.destination_port": "INVALID_MODE",
    },
    "reader": {
        "frame0.read": "NO_ERROR",
        "frame0.length": 7,
        "frame0.message": "latest",
        "frame1.read": "NO_ERROR",
        "frame1.length": 7,
        "frame1.message": "normal",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
