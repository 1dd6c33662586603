# SPDX-License-Identifier: Apache-2.0
"""CREATE_ERROR_HANDLER (NO_ERROR, NO_ACTION, INVALID_CONFIG, INVALID_MODE), GET_ERROR_STATUS
(NO_ERROR, NO_ACTION, INVALID_CONFIG), RAISE_APPLICATION_ERROR (NO_ERROR, INVALID_PARAM) and
REPORT_APPLICATION_MESSAGE (NO_ERROR, INVALID_PARAM), ARINC 653 Part 1, 3.10: an application
error handled at process level reaches the error handler, which runs before the raising
process goes on."""

FRAMES = 3

CHECKS = {
    "handled": {
        "create.stack_zero": "INVALID_CONFIG",
        "create.no_entry": "INVALID_CONFIG",
        "create.ok": "NO_ERROR",
        "create.again": "NO_ACTION",
        "status.not_handler": "INVALID_CONFIG",
        "raise.wrong_code": "INVALID_PARAM",
        "raise.too_long": "INVALID_PARAM",
        "raise.negative": "INVALID_PARAM",
        "status.rc": "NO_ERROR",
        "status.code": 1,
        "status.failed": None,
        "status.message": "sensor.out.of.range",
        "status.length": 19,
        "handler.get_my_id": "INVALID_MODE",
        "handler.timed_wait": "INVALID_MODE",
        "status.drained": "NO_ACTION",
        "raise.ok": "NO_ERROR",
        "raise.handled_before_return": 1,
        "report.negative": "INVALID_PARAM",
        "report.too_long": "INVALID_PARAM",
        "report.ok": "NO_ERROR",
    },
    "plain": {"create.normal_mode": "INVALID_MODE"},
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_the_decision_is_in_the_trace(apex):
    apex.assert_ran()
    (hm,) = apex.of_kind("hm")
    assert (hm["error"], hm["level"], hm["action"], hm["partition"], hm["process"]) == (
        "APPLICATION_ERROR", "PROCESS", "ERROR_HANDLER", "handled", "worker")
    assert hm["message"] == "sensor out of range"
