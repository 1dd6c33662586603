# SPDX-License-Identifier: Apache-2.0
"""START (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_PARAM: no such process; NO_ACTION: the process is not DORMANT; INVALID_CONFIG: its
DEADLINE_TIME calculation is out of range; NO_ERROR otherwise.
"""

FRAMES = 3

CHECKS = {
    "starter": {
        "init.id_zero": "INVALID_PARAM",
        "init.id_negative": "INVALID_PARAM",
        "init.id_unknown": "INVALID_PARAM",
        "init.dormant": "NO_ERROR",
        "init.already_started": "NO_ACTION",
        "init.periodic": "NO_ERROR",
        "normal.self_running": "NO_ACTION",
        "normal.ready.state": "READY",
        "normal.ready": "NO_ACTION",
        "normal.dormant": "NO_ERROR",
        "normal.dormant.preempts": 1,
        "normal.dormant_again": "NO_ERROR",
        "normal.dormant_again.preempts": 2,
        "normal.waiting.state": "WAITING",
        "normal.waiting": "NO_ACTION",
        "normal.id_zero": "INVALID_PARAM",
        "normal.id_unknown": "INVALID_PARAM",
        "normal.periodic": "NO_ERROR",
        "normal.periodic.first_release": 20_000_000,
        "normal.deadline_out_of_range": "INVALID_CONFIG",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_start_is_in_the_trace(apex):
    apex.assert_ran()
    starts = [e["name"] for e in apex.of_kind("process", event="start")]
    assert starts[:2] == ["worker", "cyclic"]  # during initialisation
    assert starts.count("helper") == 2 and starts.count("late") == 1
