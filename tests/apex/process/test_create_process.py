# SPDX-License-Identifier: Apache-2.0
"""CREATE_PROCESS (ARINC 653 Part 1, 3.3.2): every return code the standard lists.

INVALID_CONFIG: the maximum number of processes is reached, or a periodic process's period is
not a multiple of the partition period; NO_ACTION: a process of that name exists;
INVALID_PARAM: stack size, priority, period or time capacity out of range, or a periodic
process's time capacity above its period; INVALID_MODE: the partition is in NORMAL mode.
Output parameters are written only on NO_ERROR.
"""

FRAMES = 2


def _refused(name: str, code: str) -> dict:
    return {name: code, f"{name}.id_untouched": 0x5A5A5A5A}


CHECKS = {
    "codes": {
        "aperiodic": "NO_ERROR",
        "aperiodic.id_written": "yes",
        "periodic": "NO_ERROR",
        "capacity_equals_period": "NO_ERROR",
        **_refused("same_name", "NO_ACTION"),
        **_refused("same_name.other_attributes", "NO_ACTION"),
        **_refused("stack_zero", "INVALID_PARAM"),
        **_refused("stack_too_large", "INVALID_PARAM"),
        **_refused("priority_below_min", "INVALID_PARAM"),
        **_refused("priority_above_max", "INVALID_PARAM"),
        **_refused("priority_negative", "INVALID_PARAM"),
        "priority_max": "NO_ERROR",
        "priority_min": "NO_ERROR",
        **_refused("period_zero", "INVALID_PARAM"),
        **_refused("period_negative", "INVALID_PARAM"),
        **_refused("period_not_multiple_30ms", "INVALID_CONFIG"),
        **_refused("period_not_multiple_10ms", "INVALID_CONFIG"),
        **_refused("capacity_zero", "INVALID_PARAM"),
        **_refused("capacity_negative", "INVALID_PARAM"),
        "capacity_aperiodic": "NO_ERROR",
        **_refused("capacity_over_period", "INVALID_PARAM"),
        "refused.not_created": "INVALID_CONFIG",
        **_refused("normal.create", "INVALID_MODE"),
        "normal.create.not_created": "INVALID_CONFIG",
    },
    "full": {
        "full.created": 128,  # MAX_NUMBER_OF_PROCESSES of this implementation
        "full.one_more": "INVALID_CONFIG",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
