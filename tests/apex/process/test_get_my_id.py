# SPDX-License-Identifier: Apache-2.0
"""GET_MY_ID (ARINC 653 Part 1, 3.3.2): NO_ERROR in a process, INVALID_MODE in the
initialisation process (which has no process identifier)."""

FRAMES = 1

CHECKS = {
    "get_my_id": {
        "init.rc": "INVALID_MODE",
        "init.id_untouched": 0x5A5A5A5A,
        "ids_distinct": "yes",
        "alpha.rc": "NO_ERROR",
        "alpha.id": None,  # the identifier CREATE_PROCESS returned
        "beta.rc": "NO_ERROR",
        "beta.id": None,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
