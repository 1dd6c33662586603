# SPDX-License-Identifier: Apache-2.0
"""GET_SEMAPHORE_ID (ARINC 653 Part 1, 3.7.2.3): every return code the standard lists.

NO_ERROR with the semaphore's identifier; INVALID_CONFIG: no semaphore of that name in the
partition (names compare exactly, on at most 30 characters).
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "get_semaphore_id": {
        "init.none_created": "INVALID_CONFIG",
        "init.none_created.id": UNTOUCHED,
        "init.distinct": "yes",
        "init.first": "NO_ERROR",
        "init.first.id": None,
        "init.second": "NO_ERROR",
        "init.second.id": None,
        "init.prefix": "INVALID_CONFIG",
        "init.prefix.id": UNTOUCHED,
        "init.longer": "INVALID_CONFIG",
        "init.longer.id": UNTOUCHED,
        "init.case": "INVALID_CONFIG",
        "init.case.id": UNTOUCHED,
        "init.empty": "INVALID_CONFIG",
        "init.empty.id": UNTOUCHED,
        "init.other_name_type": "INVALID_CONFIG",
        "init.other_name_type.id": UNTOUCHED,
        "normal.first": "NO_ERROR",
        "normal.first.id": None,
        "normal.second": "NO_ERROR",
        "normal.second.id": None,
        "normal.unknown": "INVALID_CONFIG",
        "normal.unknown.id": UNTOUCHED,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
