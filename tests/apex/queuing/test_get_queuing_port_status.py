# SPDX-License-Identifier: Apache-2.0
"""GET_QUEUING_PORT_STATUS (ARINC 653 Part 1, 3.6.2.2): NO_ERROR with the queue's state and
configuration, INVALID_PARAM for an unknown identifier (output untouched)."""

FRAMES = 2
UNTOUCHED = 0x5A5A5A5A


def _status(phase: str, nb: int, waiting: int, config: tuple | None = None) -> dict:
    table = {
        f"{phase}.rc": "NO_ERROR",
        f"{phase}.nb_message": nb,
        f"{phase}.waiting_processes": waiting,
    }
    if config:
        max_nb, direction = config
        table.update(
            {
                f"{phase}.max_nb_message": max_nb,
                f"{phase}.max_message_size": 16,
                f"{phase}.port_direction": direction,
            }
        )
    return table


BAD_IDS = {
    "id_zero": "INVALID_PARAM",
    "id_zero.untouched": UNTOUCHED,
    "id_unknown": "INVALID_PARAM",
    "id_unknown.untouched": UNTOUCHED,
    "sampling_port_id": "INVALID_PARAM",
    "sampling_port_id.untouched": UNTOUCHED,
}

CHECKS = {
    "src": {
        **_status("init", 0, 0, (3, "SOURCE")),
        **BAD_IDS,
        **_status("init.after_sending", 2, 0),
        **_status("src.full", 3, 1),
        **_status("src.later", 1, 0),
    },
    "dst": {
        **_status("init", 3, 0, (5, "DESTINATION")),
        **BAD_IDS,
        **_status("init.after_receiving", 0, 0),
        **_status("dst.two_waiting", 0, 2),
        **_status("dst.one_waiting", 0, 1),
        "dst.first_waiter_served": "m3",
        "dst.second_waiter_waits": "(none)",
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
