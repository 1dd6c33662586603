# SPDX-License-Identifier: Apache-2.0
"""REPLENISH (ARINC 653 Part 1, 3.4.2): every return code the standard lists.

NO_ACTION: not in NORMAL mode, the error handler, or a process with no deadline (infinite
TIME_CAPACITY); INVALID_PARAM: BUDGET_TIME out of range (below -1, or ending past the end of
the clock); INVALID_MODE: a periodic process's new deadline would pass its next release point
(an infinite budget included); NO_ERROR: DEADLINE_TIME becomes now + BUDGET_TIME (none for an
infinite budget).
"""

FRAMES = 2
INFINITE = -1

CHECKS = {
    "replenish": {
        "init.no_action": "NO_ACTION",
        "nocap.no_action": "NO_ACTION",
        "nocap.no_action.deadline": INFINITE,
        "periodic.release.deadline": 10_000_000,
        "periodic": "NO_ERROR",
        "periodic.deadline": 5_000_000,
        "periodic.up_to_next_release": "NO_ERROR",
        "periodic.up_to_next_release.deadline": 20_000_000,
        "periodic.past_next_release": "INVALID_MODE",
        "periodic.past_next_release.deadline": 20_000_000,
        "periodic.infinite": "INVALID_MODE",
        "periodic.infinite.deadline": 20_000_000,
        "periodic.budget_minus_2": "INVALID_PARAM",
        "periodic.budget_minus_2.deadline": 20_000_000,
        "periodic.next.deadline": 30_000_000,
        # at 1 ms
        "aperiodic": "NO_ERROR",
        "aperiodic.deadline": 4_000_000,
        "aperiodic.budget_minus_2": "INVALID_PARAM",
        "aperiodic.budget_minus_2.deadline": 4_000_000,
        "aperiodic.budget_beyond_clock": "INVALID_PARAM",
        "aperiodic.budget_beyond_clock.deadline": 4_000_000,
        "aperiodic.infinite": "NO_ERROR",
        "aperiodic.infinite.deadline": INFINITE,
        "aperiodic.again": "NO_ERROR",
        "aperiodic.again.deadline": 3_000_000,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_no_deadline_missed(apex):
    apex.assert_ran()
    assert apex.of_kind("hm") == []
