# SPDX-License-Identifier: Apache-2.0
"""STOP_SELF (ARINC 653 Part 1, 3.3.2): the process becomes DORMANT and can be started again.

STOP_SELF has no return code; GET_PROCESS_STATUS and START show its effect.
"""

FRAMES = 3

CHECKS = {
    "stopper": {
        "aperiodic.runs": 1,
        "aperiodic.state": "DORMANT",
        "aperiodic.start_again": "NO_ERROR",
        "aperiodic.runs_again": 2,
        "aperiodic.state_again": "DORMANT",
        "periodic.runs": 1,
        "periodic.state": "DORMANT",
        "periodic.start_again": "NO_ERROR",
        "periodic.runs_again": 2,
        "periodic.state_again": "DORMANT",
        "periodic.first_release": 0,
        "periodic.release_after_restart": 20_000_000,
        "never_returns": 0,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_every_stop_is_in_the_trace(apex):
    apex.assert_ran()
    stops = [e["name"] for e in apex.of_kind("process", event="stop")]
    assert stops.count("victim") == 2 and stops.count("cyclic") == 2
