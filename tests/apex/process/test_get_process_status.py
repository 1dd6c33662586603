# SPDX-License-Identifier: Apache-2.0
"""GET_PROCESS_STATUS (ARINC 653 Part 1, 3.3.2): NO_ERROR with the process's attributes,
state, priority and deadline; INVALID_PARAM for an unknown identifier."""

FRAMES = 2
INFINITE = -1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "get_process_status": {
        "init.dormant": "DORMANT",
        "init.name": "never",
        "init.base_priority": 7,
        "init.current_priority": 7,
        "init.period": INFINITE,
        "init.time_capacity": 5_000_000,
        "init.stack_size": 131072,
        "init.deadline": "HARD",
        "init.entry_point": "yes",
        "init.periodic.period": 20_000_000,
        "init.periodic.time_capacity": 8_000_000,
        "init.id_zero": "INVALID_PARAM",
        "init.id_zero.untouched": UNTOUCHED,
        "init.id_negative": "INVALID_PARAM",
        "init.id_negative.untouched": UNTOUCHED,
        "init.id_unknown": "INVALID_PARAM",
        "init.id_unknown.untouched": UNTOUCHED,
        "init.started": "WAITING",
        "normal.self": "RUNNING",
        "normal.self.deadline": INFINITE,
        "normal.lower_priority": "READY",
        "normal.lower_priority.current_priority": 10,
        "normal.lower_priority.deadline": 50_000_000,  # started at 0, time capacity 50 ms
        "normal.timed_wait": "WAITING",
        "normal.periodic_wait": "WAITING",
        "normal.never_started": "DORMANT",
        "normal.id_zero": "INVALID_PARAM",
        "normal.id_zero.untouched": UNTOUCHED,
        # release + time capacity (8 ms), releases at 0 and 20 ms
        "cyclic.deadline.0": 8_000_000,
        "cyclic.deadline.1": 28_000_000,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
