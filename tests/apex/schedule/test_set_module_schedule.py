# SPDX-License-Identifier: Apache-2.0
"""SET_MODULE_SCHEDULE, GET_MODULE_SCHEDULE_STATUS, GET_MODULE_SCHEDULE_ID (ARINC 653 Part 2):
NO_ERROR, INVALID_PARAM (no such schedule), INVALID_CONFIG (the partition may not change the
schedule; no schedule of that name, output untouched); the switch takes effect at the next
major frame, and the windows follow the new schedule from then on."""

FRAMES = 6
MAF = 40_000_000
SWITCH_FRAME = 3  # requested in frame 2 (release 3), effective at the next frame

CHECKS = {
    "switcher": {
        "id.degraded": "NO_ERROR",
        "id.degraded.value": 2,
        "id.unknown": "INVALID_CONFIG",
        "id.unknown.untouched": 0x5A5A5A5A,
        "init.status": "NO_ERROR",
        "init.current": 1,
        "init.next": 1,
        "init.last_switch": 0,
        "switch.unknown_id": "INVALID_PARAM",
        "switch.degraded": "NO_ERROR",
        "after_request.status": "NO_ERROR",
        "after_request.current": 1,
        "after_request.next": 2,
        "after_request.last_switch": 0,
        "after_switch.status": "NO_ERROR",
        "after_switch.current": 2,
        "after_switch.next": 2,
        "after_switch.last_switch": SWITCH_FRAME * MAF,
    },
    "other": {"switch.not_allowed": "INVALID_CONFIG"},
    "watcher": {},
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_the_switch_happens_at_the_next_major_frame(apex):
    apex.assert_ran()
    (switch,) = apex.of_kind("schedule_switch")
    assert (switch["from"], switch["to"], switch["name"]) == (1, 2, "DEGRADED")
    assert switch["t_ns"] == SWITCH_FRAME * MAF and switch["frame"] == SWITCH_FRAME
    (request,) = apex.of_kind("schedule_request")
    assert request["partition"] == "switcher" and request["schedule"] == 2
    assert request["t_ns"] < switch["t_ns"]


def test_windows_follow_the_schedule_in_force(apex):
    apex.assert_ran()
    starts = [(e["frame"], e["partition"], e["t_ns"] - e["frame"] * MAF)
              for e in apex.of_kind("window_start")]
    nominal = [("switcher", 0), ("other", 10_000_000), ("watcher", 20_000_000)]
    degraded = [("switcher", 0), ("watcher", 10_000_000)]
    for frame in range(FRAMES):
        got = [(p, off) for f, p, off in starts if f == frame]
        assert got == (nominal if frame < SWITCH_FRAME else degraded), frame
