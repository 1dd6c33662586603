# SPDX-License-Identifier: Apache-2.0
"""PERIODIC_WAIT (ARINC 653 Part 1, 3.4.2): NO_ERROR, INVALID_MODE (the caller is not a
periodic process), and the release points: a periodic process started before NORMAL mode is
released at the partition's first period start, then exactly PERIOD apart, each time with
DEADLINE_TIME = release point + TIME_CAPACITY (here half the period)."""

FRAMES = 6
RELEASES = 6


def _releases(name: str, period_ns: int) -> dict:
    table = {f"{name}.errors": 0, f"{name}.first_release": 0}
    for k in range(1, RELEASES):
        table[f"{name}.release_interval.{k}"] = period_ns
    for k in range(RELEASES):
        table[f"{name}.deadline.{k}"] = k * period_ns + period_ns // 2
    return table


CHECKS = {
    "cyclic": {
        "init": "INVALID_MODE",
        "aperiodic": "INVALID_MODE",
        **_releases("p10", 10_000_000),
        **_releases("p20", 20_000_000),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
