# SPDX-License-Identifier: Apache-2.0
"""CREATE_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2): every return code the standard lists.

INVALID_CONFIG: not enough storage for the blackboard, or MAX_NUMBER_OF_BLACKBOARDS already
created; NO_ACTION: a blackboard of that name exists; INVALID_PARAM: MAX_MESSAGE_SIZE out of
range (null, negative, above the system limit; here also an empty name); INVALID_MODE: the
partition is in NORMAL mode; NO_ERROR: the blackboard exists, EMPTY.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def create(prefix, rc):
    return {prefix: rc, f"{prefix}.id": None if rc == "NO_ERROR" else UNTOUCHED}


CHECKS = {
    "create": {
        **create("init.created", "NO_ERROR"),
        "init.created.empty_indicator": "EMPTY",
        "init.created.max_message_size": 16,
        **create("init.same_name", "NO_ACTION"),
        **create("init.size_zero", "INVALID_PARAM"),
        **create("init.size_negative", "INVALID_PARAM"),
        **create("init.size_over_limit", "INVALID_PARAM"),
        **create("init.empty_name", "INVALID_PARAM"),
        **create("init.largest", "NO_ERROR"),
        **create("normal.new", "INVALID_MODE"),
        **create("normal.existing", "NO_ACTION"),
    },
    "limits": {
        "limits.created": 255,
        **create("limits.storage", "INVALID_CONFIG"),
        **create("limits.last", "NO_ERROR"),
        **create("limits.one_more", "INVALID_CONFIG"),
        **create("limits.existing_name", "INVALID_CONFIG"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
