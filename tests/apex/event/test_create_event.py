# SPDX-License-Identifier: Apache-2.0
"""CREATE_EVENT (ARINC 653 Part 1, 3.7.2.4): every return code the standard lists.

INVALID_CONFIG: MAX_NUMBER_OF_EVENTS already created (an event needs no other storage);
NO_ACTION: an event of that name exists; INVALID_PARAM (this implementation): an empty name;
INVALID_MODE: the partition is in NORMAL mode; NO_ERROR: the event exists, DOWN.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def create(prefix, rc):
    out = {prefix: rc, f"{prefix}.id": None if rc == "NO_ERROR" else UNTOUCHED}
    if rc == "NO_ERROR":
        out[f"{prefix}.state"] = "DOWN"
    return out


CHECKS = {
    "create": {
        **create("init.created", "NO_ERROR"),
        **create("init.same_name", "NO_ACTION"),
        **create("init.empty_name", "INVALID_PARAM"),
        **create("init.second", "NO_ERROR"),
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
