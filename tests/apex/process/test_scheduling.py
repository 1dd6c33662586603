# SPDX-License-Identifier: Apache-2.0
"""Process scheduling (ARINC 653 Part 1, 2.3.2): highest priority first, FIFO within a
priority, preemption by a higher-priority process only."""

FRAMES = 1

CHECKS = {
    "scheduling": {
        "priority_then_fifo": "high,midA,midB,low",
        "start_preempts_lower": "urgent,low",
        "start_keeps_equal": "low,peer",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
