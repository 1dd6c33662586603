# SPDX-License-Identifier: Apache-2.0
"""CREATE_SEMAPHORE (ARINC 653 Part 1, 3.7.2.3): every return code the standard lists.

INVALID_CONFIG: MAX_NUMBER_OF_SEMAPHORES already created (a semaphore needs no other
storage); NO_ACTION: a semaphore of that name exists; INVALID_PARAM: CURRENT_VALUE or
MAXIMUM_VALUE outside 0..MAX_SEMAPHORE_VALUE, CURRENT_VALUE above MAXIMUM_VALUE,
QUEUING_DISCIPLINE invalid (here also an empty name); INVALID_MODE: the partition is in
NORMAL mode; NO_ERROR: the semaphore exists with those values.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def create(prefix, rc, values=None):
    out = {prefix: rc, f"{prefix}.id": None if rc == "NO_ERROR" else UNTOUCHED}
    if values:
        out[f"{prefix}.values"] = values  # current/maximum/waiting
    return out


CHECKS = {
    "create": {
        **create("init.created", "NO_ERROR", "0/1/0"),
        **create("init.same_name", "NO_ACTION"),
        **create("init.current_negative", "INVALID_PARAM"),
        **create("init.current_over_limit", "INVALID_PARAM"),
        **create("init.maximum_negative", "INVALID_PARAM"),
        **create("init.maximum_over_limit", "INVALID_PARAM"),
        **create("init.current_above_maximum", "INVALID_PARAM"),
        **create("init.discipline", "INVALID_PARAM"),
        **create("init.empty_name", "INVALID_PARAM"),
        **create("init.largest", "NO_ERROR", "32767/32767/0"),
        **create("init.maximum_zero", "NO_ERROR", "0/0/0"),
        **create("normal.new", "INVALID_MODE"),
        **create("normal.existing", "NO_ACTION"),
    },
    "limits": {
        "limits.created": 256,
        **create("limits.one_more", "INVALID_CONFIG"),
        **create("limits.existing_name", "INVALID_CONFIG"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
