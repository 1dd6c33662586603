# SPDX-License-Identifier: Apache-2.0
"""GET_BUFFER_STATUS (ARINC 653 Part 1, 3.7.2.1): every return code the standard lists.

NO_ERROR with NB_MESSAGE, MAX_NB_MESSAGE, MAX_MESSAGE_SIZE and WAITING_PROCESSES (senders
waiting on a full buffer, receivers on an empty one); INVALID_PARAM: no such buffer.
"""

FRAMES = 1
UNTOUCHED = 0x5A5A5A5A

CHECKS = {
    "get_buffer_status": {
        "init.empty.nb_message": 0,
        "init.empty.max_nb_message": 3,
        "init.empty.max_message_size": 16,
        "init.empty.waiting_processes": 0,
        "init.two_messages.nb_message": 2,
        "init.full.nb_message": 3,
        "init.other.max_nb_message": 1,
        "init.other.max_message_size": 4,
        "init.id_zero": "INVALID_PARAM",
        "init.id_zero.untouched": UNTOUCHED,
        "init.id_negative": "INVALID_PARAM",
        "init.id_negative.untouched": UNTOUCHED,
        "init.id_unknown": "INVALID_PARAM",
        "init.id_unknown.untouched": UNTOUCHED,
        "normal.receivers.nb_message": 0,
        "normal.receivers.waiting": 2,
        "normal.senders.nb_message": 3,
        "normal.senders.waiting": 2,
        "normal.one_received.waiting": 1,
        "normal.id_unknown": "INVALID_PARAM",
        "normal.id_unknown.untouched": UNTOUCHED,
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
