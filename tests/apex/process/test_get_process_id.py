# SPDX-License-Identifier: Apache-2.0
"""GET_PROCESS_ID (ARINC 653 Part 1, 3.3.2): NO_ERROR, INVALID_CONFIG for an unknown name."""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def _lookups(phase: str) -> dict:
    table = {}
    for name in ("alpha", "beta", "full_length_name"):
        table[f"{phase}.{name}"] = "NO_ERROR"
        table[f"{phase}.{name}.id"] = None  # the identifier CREATE_PROCESS returned
    for name in ("unknown", "prefix", "longer", "empty"):
        table[f"{phase}.{name}"] = "INVALID_CONFIG"
        table[f"{phase}.{name}.id"] = UNTOUCHED
    return table


CHECKS = {"get_process_id": {**_lookups("init"), **_lookups("normal")}}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
