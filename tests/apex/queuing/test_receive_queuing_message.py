# SPDX-License-Identifier: Apache-2.0
"""RECEIVE_QUEUING_MESSAGE (ARINC 653 Part 1, 3.6.2.2): every return code the standard lists.

INVALID_PARAM: no such queuing port, TIME_OUT out of range (below -1 or beyond the end of
the clock); INVALID_MODE: the port is not a
destination, or the caller would have to wait and may not (the initialisation process);
NOT_AVAILABLE: empty and TIME_OUT is 0; TIMED_OUT: still empty when the time-out expires;
INVALID_CONFIG: the queue overflowed since the last receive (the message is still returned);
NO_ERROR otherwise. Messages sent in the source's window reach the destination when that
window ends. LENGTH is 0 when no message is received (NOT_AVAILABLE, TIMED_OUT, a wait
refused with INVALID_MODE); INVALID_PARAM and the source port's INVALID_MODE leave every
output alone (docs/apex-coverage.md, output parameters).
"""

FRAMES = 2


def _refused(name: str, code: str) -> dict:
    return {name: code, f"{name}.outputs_written": "none"}


def _nothing(name: str, code: str) -> dict:
    """No message received: LENGTH 0 and nothing else written."""
    return {name: code, f"{name}.outputs_written": "LENGTH=0,"}


def _received(name: str, code: str, text: str) -> dict:
    return {name: code, f"{name}.message": text, f"{name}.length": len(text) + 1}


CHECKS = {
    "src": {
        "src.nb_message.after_window_a": 0,
        "src.nb_message.in_window_b": 1,
    },
    "dst": {
        **_nothing("init.empty.would_wait", "INVALID_MODE"),
        **_nothing("init.empty.would_wait_forever", "INVALID_MODE"),
        **_nothing("init.empty.no_wait", "NOT_AVAILABLE"),
        **_refused("id_zero", "INVALID_PARAM"),
        **_refused("id_unknown", "INVALID_PARAM"),
        **_refused("timeout_minus_2", "INVALID_PARAM"),
        **_refused("source_port", "INVALID_MODE"),
        "nb_message": 1,
        **_received("received", "NO_ERROR", "A0"),
        **_nothing("empty.no_wait", "NOT_AVAILABLE"),
        **_nothing("empty.timed_out", "TIMED_OUT"),
        "empty.timed_out.elapsed": 1_000_000,
        **_refused("timeout_beyond_clock", "INVALID_PARAM"),
        "timeout_beyond_clock.elapsed": 0,
        **_received("overflow", "INVALID_CONFIG", "F0"),
        **_received("overflow.next", "NO_ERROR", "F1"),
        **_nothing("overflow.lost", "NOT_AVAILABLE"),
        **_received("wait", "NO_ERROR", "B0"),
        "wait.received_at": 25_000_000,
        **_received("wait.next", "NO_ERROR", "A1"),
        **_nothing("wait.then", "NOT_AVAILABLE"),
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_overflow_is_in_the_trace(apex):
    apex.assert_ran()
    overflows = apex.of_kind("port", event="overflow")
    # F2 and F3 did not fit, when the SKE moved them at the end of src's window A (4 ms).
    assert [(e["t_ns"], e["channel"], e["partition"], e["port"]) for e in overflows] == [
        (4_000_000, "flood", "dst", "QP_SMALL")
    ] * 2
    flood = {c["name"]: c for c in apex.run.stats["channels"]}["flood"]
    assert (flood["messages"], flood["overflows"]) == (2, 2)


def test_messages_move_when_the_source_window_ends(apex):
    apex.assert_ran()
    # Window A ends at 4 ms, before dst's window (5 ms): A0 is there, B0 (window B) is not.
    assert {"CHECK nb_message expect=1 got=1"} <= set(apex.messages("dst"))
    commands = {c["name"]: c for c in apex.run.stats["channels"]}["commands"]
    assert commands["messages"] == 4  # A0, B0, A1, B1 in two frames
