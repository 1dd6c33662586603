# SPDX-License-Identifier: Apache-2.0
"""The schedule timeline drawn in the run summary."""

from ima.ske import timeline

STATS = {
    "major_frame_ns": 50_000_000,
    "windows": [
        {"window": 1, "partition": "producer", "offset_ns": 0, "duration_ns": 10_000_000},
        {"window": 2, "partition": "consumer", "offset_ns": 10_000_000, "duration_ns": 12_000_000},
        {"window": 5, "partition": "monitor", "offset_ns": 38_000_000, "duration_ns": 8_000_000},
    ],
}


def test_one_cell_per_millisecond_shows_each_window_where_it_is():
    row = "".join(ch for ch, _ in timeline(STATS, width=50))
    assert row == "P" * 10 + "C" * 12 + "·" * 16 + "M" * 8 + "·" * 4


def test_a_cell_goes_to_the_window_covering_most_of_it():
    cells = timeline(STATS, width=5)  # 10 ms per cell
    assert [name for _, name in cells] == ["producer", "consumer", "consumer", "monitor", "monitor"]


def test_no_windows_no_timeline():
    assert timeline({"major_frame_ns": 50_000_000}) == []
    assert timeline({}) == []


def test_partitions_sharing_an_initial_get_distinct_letters():
    stats = {
        "major_frame_ns": 30,
        "partitions": [{"name": "spin"}, {"name": "sink"}, {"name": "stopper"}],
        "windows": [
            {"window": 1, "partition": "spin", "offset_ns": 0, "duration_ns": 10},
            {"window": 2, "partition": "sink", "offset_ns": 10, "duration_ns": 10},
            {"window": 3, "partition": "stopper", "offset_ns": 20, "duration_ns": 10},
        ],
    }
    assert "".join(ch for ch, _ in timeline(stats, width=3)) == "SIT"


def test_the_run_lines_count_health_monitor_decisions():
    from ima.ske import run_lines

    stats = {"mode": "emulated", "frames": 10, "emulated_ns": 500_000_000, "wall_s": 0.01,
             "hm_events": 7, "partitions": [{"restarts": 2}, {"restarts": 1}]}
    assert "Health monitor: 7 decisions, 3 partition restarts" in "\n".join(run_lines(stats))
    assert not any("Health monitor" in line for line in run_lines({**stats, "hm_events": 0}))
