# SPDX-License-Identifier: Apache-2.0
"""READ_SAMPLING_MESSAGE_CONDITIONAL (ARINC 653 Part 2, sampling port extensions): every return
code the standard lists.

NO_ERROR: the latest message is newer than REF_TIME_STAMP: the message, LENGTH and its
TIME_STAMP; NO_ACTION: it is not (LENGTH 0, TIME_STAMP the message's) or the port is empty
(LENGTH 0, TIME_STAMP 0), the message buffer left alone; INVALID_PARAM: no such sampling port,
REF_TIME_STAMP negative; INVALID_MODE: not a destination port. The errors write no output.
"""

FRAMES = 3


def _call(name: str, code: str, outputs: str) -> dict:
    return {name: code, f"{name}.outputs": outputs}


CHECKS = {
    "writer": {},
    "reader": {
        **_call("empty", "NO_ACTION", "LENGTH=0,TIME_STAMP=0,"),
        **_call("id_zero", "INVALID_PARAM", "none"),
        **_call("id_unknown", "INVALID_PARAM", "none"),
        **_call("source_port", "INVALID_MODE", "none"),
        **_call("ref_negative", "INVALID_PARAM", "none"),
        **_call("ref_infinite", "INVALID_PARAM", "none"),
        **_call("newer", "NO_ERROR", "LENGTH=5,TIME_STAMP=2000000,MESSAGE=msg0,"),
        **_call("same_time", "NO_ACTION", "LENGTH=0,TIME_STAMP=2000000,"),
        **_call("older", "NO_ACTION", "LENGTH=0,TIME_STAMP=2000000,"),
        **_call("next", "NO_ERROR", "LENGTH=5,TIME_STAMP=42000000,MESSAGE=msg2,"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)
