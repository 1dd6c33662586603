# SPDX-License-Identifier: Apache-2.0
"""READ_UPDATED_SAMPLING_MESSAGE (ARINC 653 Part 2, sampling port extensions): every return
code the standard lists.

NO_ERROR with UPDATED = NEW_MESSAGE: the latest message, not read yet through this port;
NO_ACTION with UPDATED = CONSUMED_MESSAGE (read already, by this service or by
READ_SAMPLING_MESSAGE) or EMPTY_PORT (nothing ever written), LENGTH 0 and the message buffer
left alone; INVALID_PARAM: no such sampling port; INVALID_MODE: not a destination port. The
errors write no output.
"""

FRAMES = 4


def _call(name: str, code: str, outputs: str) -> dict:
    return {name: code, f"{name}.outputs": outputs}


CHECKS = {
    "writer": {},
    "reader": {
        **_call("empty", "NO_ACTION", "LENGTH=0,UPDATED=EMPTY_PORT,"),
        **_call("id_zero", "INVALID_PARAM", "none"),
        **_call("id_unknown", "INVALID_PARAM", "none"),
        **_call("source_port", "INVALID_MODE", "none"),
        **_call("new", "NO_ERROR", "LENGTH=5,UPDATED=NEW_MESSAGE,MESSAGE=msg0,"),
        **_call("consumed", "NO_ACTION", "LENGTH=0,UPDATED=CONSUMED_MESSAGE,"),
        **_call("still_consumed", "NO_ACTION", "LENGTH=0,UPDATED=CONSUMED_MESSAGE,"),
        **_call("consumed_by_read", "NO_ACTION", "LENGTH=0,UPDATED=CONSUMED_MESSAGE,"),
        **_call("new_again", "NO_ERROR", "LENGTH=5,UPDATED=NEW_MESSAGE,MESSAGE=msg3,"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_validity_changes_of_updated_reads_are_in_the_trace(apex):
    apex.assert_ran()
    changes = [
        (e["t_ns"], e["event"]) for e in apex.of_kind("port", partition="reader", port="SP_IN")
    ]
    # Every read that delivers a message sets LAST_MSG_VALIDITY: valid at 10, 50 and 70 ms
    # (messages 8 ms old); nothing is delivered at 30 ms.
    assert changes == [(10_000_000, "valid")]
