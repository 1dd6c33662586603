# SPDX-License-Identifier: Apache-2.0
"""GET_SAMPLING_PORT_ID (ARINC 653 Part 1, 3.6.2.1): NO_ERROR, and INVALID_CONFIG when the
partition has no created sampling port of that name. Output written only on NO_ERROR."""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def _lookups(phase: str) -> dict:
    table = {}
    for name in ("source", "destination"):
        table[f"{phase}.{name}"] = "NO_ERROR"
        table[f"{phase}.{name}.id"] = None  # the identifier CREATE_SAMPLING_PORT returned
    for name in ("configured_not_created", "unknown", "prefix", "empty", "queuing_port"):
        table[f"{phase}.{name}"] = "INVALID_CONFIG"
        table[f"{phase}.{name}.id"] = UNTOUCHED
    return table


CHECKS = {"ids": {**_lookups("init"), **_lookups("normal")}}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
