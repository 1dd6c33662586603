# SPDX-License-Identifier: Apache-2.0
"""GET_TIME (ARINC 653 Part 1, 3.4.2): NO_ERROR (its only return code) and the emulated
time it reports: window start, release points, no time for computation."""

FRAMES = 4


def _times(offset_ns: int) -> dict:
    return {
        "init.rc": "NO_ERROR",
        "init": offset_ns,
        "init.after_computing": offset_ns,
        **{f"release.{k}.rc": "NO_ERROR" for k in range(4)},
        **{f"release.{k}": offset_ns + k * 20_000_000 for k in range(4)},
    }


CHECKS = {"first": _times(0), "clock": _times(5_000_000)}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
