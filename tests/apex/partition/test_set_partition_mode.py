# SPDX-License-Identifier: Apache-2.0
"""SET_PARTITION_MODE (ARINC 653 Part 1, 3.2.2): every return code, IDLE and the restarts."""

FRAMES = 6
FRAME_NS = 30_000_000

CHECKS = {
    "codes": {
        "init.mode": "COLD_START",
        "init.warm_start_in_cold_start": "INVALID_MODE",
        "init.mode_4": "INVALID_PARAM",
        "init.mode_minus_1": "INVALID_PARAM",
        "init.mode_after": "COLD_START",
        "init.normal": "NO_ERROR",  # read by a process: the call does not return
        "normal.mode": "NORMAL",
        "normal.normal_again": "NO_ACTION",
        "normal.mode_4": "INVALID_PARAM",
        "normal.mode_after": "NORMAL",
    },
    # These two report what they see as plain lines; the table keeps their set-up checked.
    "idler": {},
    "restarter": {},
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_idle_stops_the_partition_for_good(apex):
    apex.assert_ran()
    assert apex.lines("idler", "TICK ") == ["TICK 0", "TICK 1", "TICK 2"]
    modes = apex.of_kind("mode", partition="idler")
    assert [(e["mode"], e["from"]) for e in modes] == [
        ("COLD_START", "IDLE"),
        ("NORMAL", "COLD_START"),
        ("IDLE", "NORMAL"),
    ]
    idle = modes[-1]
    assert idle["reason"] == "SET_PARTITION_MODE"
    assert idle["t_ns"] == 2 * FRAME_NS + 15_000_000  # the end of its third window
    windows = apex.windows("idler")
    assert len(windows) == FRAMES
    assert all("partition_state" not in w for w in windows[:3])
    assert [w.get("partition_state") for w in windows[3:]] == ["idle"] * (FRAMES - 3)
    later = [e for e in apex.events if e["src"] == "idler" and e["t_ns"] > idle["t_ns"]]
    assert later == []
    assert {p["name"]: p["state"] for p in apex.run.stats["partitions"]}["idler"] == "idle"


def test_others_keep_their_windows_while_one_is_idle(apex):
    apex.assert_ran()
    for name in ("codes", "restarter"):
        windows = apex.windows(name)
        assert [w["frame"] for w in windows] == list(range(FRAMES))
        assert all("partition_state" not in w for w in windows)


def test_cold_start_then_warm_start_restart_the_partition(apex):
    apex.assert_ran()
    assert apex.lines("restarter", "BOOT ") == [
        "BOOT start=NORMAL_START mode=COLD_START",
        "BOOT start=PARTITION_RESTART mode=COLD_START",
        "BOOT start=PARTITION_RESTART mode=WARM_START",
    ]
    assert apex.lines("restarter", "REQUEST ") == ["REQUEST COLD_START", "REQUEST WARM_START"]
    assert apex.lines("restarter", "STAYING") == ["STAYING"]
    modes = apex.of_kind("mode", partition="restarter")
    assert [(e["mode"], e["from"]) for e in modes] == [
        ("COLD_START", "IDLE"),
        ("NORMAL", "COLD_START"),
        ("COLD_START", "NORMAL"),
        ("NORMAL", "COLD_START"),
        ("WARM_START", "NORMAL"),
        ("NORMAL", "WARM_START"),
    ]
    window_end = 25_000_000
    assert [(e["t_ns"], e.get("reason")) for e in modes if e["from"] == "NORMAL"] == [
        (window_end, "SET_PARTITION_MODE"),
        (FRAME_NS + window_end, "SET_PARTITION_MODE"),
    ]
    # Each start runs the initialisation again, in the partition's next window.
    boots = [
        e["t_ns"]
        for e in apex.of_kind("app_message")
        if e["src"] == "restarter" and e["text"].startswith("BOOT ")
    ]
    assert boots == [20_000_000, FRAME_NS + 20_000_000, 2 * FRAME_NS + 20_000_000]
    stats = {p["name"]: p for p in apex.run.stats["partitions"]}["restarter"]
    assert stats["restarts"] == 2 and stats["state"] == "running"
