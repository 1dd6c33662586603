# SPDX-License-Identifier: Apache-2.0
"""CREATE_BUFFER (ARINC 653 Part 1, 3.7.2.1): every return code the standard lists.

INVALID_CONFIG: not enough storage for the buffer, or MAX_NUMBER_OF_BUFFERS already created;
NO_ACTION: a buffer of that name exists; INVALID_PARAM: MAX_MESSAGE_SIZE or MAX_NB_MESSAGE
out of range (null, negative, above the system limits), QUEUING_DISCIPLINE invalid (and, in
this implementation, an empty name); INVALID_MODE: the partition is in NORMAL mode;
NO_ERROR: the buffer exists, empty, with the identifier GET_BUFFER_ID gives.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A


def create(prefix, rc):
    return {prefix: rc, f"{prefix}.id": None if rc == "NO_ERROR" else UNTOUCHED}


CHECKS = {
    "create": {
        **create("init.created", "NO_ERROR"),
        **create("init.same_name", "NO_ACTION"),
        **create("init.size_zero", "INVALID_PARAM"),
        **create("init.size_negative", "INVALID_PARAM"),
        **create("init.size_over_limit", "INVALID_PARAM"),
        **create("init.nb_zero", "INVALID_PARAM"),
        **create("init.nb_negative", "INVALID_PARAM"),
        **create("init.nb_over_limit", "INVALID_PARAM"),
        **create("init.discipline", "INVALID_PARAM"),
        **create("init.empty_name", "INVALID_PARAM"),
        **create("init.storage", "INVALID_CONFIG"),
        **create("init.priority", "NO_ERROR"),
        **create("init.full_length_name", "NO_ERROR"),
        "init.created.max_message_size": 16,
        "init.created.max_nb_message": 4,
        "init.created.nb_message": 0,
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
