# SPDX-License-Identifier: Apache-2.0
"""Destination port memory is mapped read-only (ARINC 653 Part 1, spatial
partitioning): a partition that writes through it faults (SIGSEGV), the health monitor reports a
MEMORY_VIOLATION and idles it (the default tables), the others keep their schedule and the
channel keeps the source's data."""

FRAMES = 5

CHECKS = {
    "writer": {},
    "vandal": {
        "vandal.read": "NO_ERROR",
        "vandal.found_read_only_mapping": "yes",
        "vandal.mprotect_write": "EACCES",
    },
    "reader": {
        **{f"frame{k}.read": "NO_ERROR" for k in range(FRAMES)},
        **{f"frame{k}.value": k for k in range(FRAMES)},
    },
}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_the_write_is_a_memory_violation_and_idles_the_vandal(apex):
    apex.assert_ran()
    assert apex.lines("vandal", "VANDAL ")[-1] == "VANDAL writing"
    assert apex.of_kind("partition_exit") == []  # caught, not a crash of the process
    (hm,) = apex.of_kind("hm")
    assert (hm["error"], hm["level"], hm["action"], hm["partition"]) == (
        "MEMORY_VIOLATION", "PARTITION", "IDLE", "vandal")
    assert hm["message"].startswith("SIGSEGV at address")
    windows = apex.windows("vandal")
    assert "partition_state" not in windows[0]
    assert [w.get("partition_state") for w in windows[1:]] == ["idle"] * (FRAMES - 1)
    stats = {p["name"]: p for p in apex.run.stats["partitions"]}
    assert stats["vandal"]["state"] == "idle"


def test_the_others_keep_their_schedule(apex):
    apex.assert_ran()
    for name in ("writer", "reader"):
        ends = apex.of_kind("window_end", partition=name)
        assert [e["frame"] for e in ends] == list(range(FRAMES))
        assert all(e["yielded"] for e in ends)
        assert all("partition_state" not in w for w in apex.windows(name))
    assert apex.of_kind("overrun") == []
