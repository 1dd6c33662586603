# SPDX-License-Identifier: Apache-2.0
"""GET_PARTITION_STATUS (ARINC 653 Part 1, 3.2.2): NO_ERROR and the configured status."""

FRAMES = 2


def _status(period_ns: int, duration_ns: int, identifier: int, phase: str, mode: str) -> dict:
    table = {
        f"{phase}.rc": "NO_ERROR",
        f"{phase}.period": period_ns,
        f"{phase}.duration": duration_ns,
        f"{phase}.identifier": identifier,
        f"{phase}.operating_mode": mode,
        f"{phase}.start_condition": "NORMAL_START",
        f"{phase}.num_assigned_cores": 1,
    }
    if mode == "NORMAL":
        table[f"{phase}.lock_level"] = 0
    return table


CHECKS = {
    name: {
        **_status(period, duration, ident, "init", "COLD_START"),
        **_status(period, duration, ident, "normal", "NORMAL"),
    }
    for name, period, duration, ident in [
        ("status", 20_000_000, 4_000_000, 7),
        ("other", 40_000_000, 8_000_000, 3),
    ]
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
