# SPDX-License-Identifier: Apache-2.0
"""The DDS benchmark's parsing of ddsperf (the measurement itself runs in `ima bench`, not here)."""

from __future__ import annotations

import pytest

from ima.bench import dds as bench
from ima.errors import ImaError

SAMPLE = """\
[3437] participant vm:3437: new (self)
[3437] 1.000  vm:3425 size 12 mean 25.707us min 8.837us 50% 15.342us 90% 36.318us 99% 91.021us max 1035.282us cnt 494
[3437] 1.000  rss:7.3MB vcsw:1089 ivcsw:242 ddsperf:2%+0%
[3437] 2.000  vm:3425 size 12 mean 42.659us min 9.368us 50% 41.266us 90% 61.246us 99% 101.967us max 974.739us cnt 499
[3437] ping timed out (total 6 times) ... sending new ping
[3437] 3.000  vm:3425 size 12 mean 41.583us min 9.128us 50% 34.105us 90% 58.832us 99% 143.063us max 1140.085us cnt 497
[3437] 4.000  vm:3425 size 12 mean 33.318us min 9.118us 50% 21.727us 90% 49.051us 99% 108.166us max 1965.818us cnt 496
"""  # noqa: E501


def test_parse_ddsperf_skips_the_first_second():
    r = bench.parse_ddsperf(SAMPLE)
    assert r == {"median": 34.1, "p90": 58.8, "count": 499 + 497 + 496}


def test_parse_ddsperf_without_pongs():
    with pytest.raises(ImaError):
        bench.parse_ddsperf("[1] participant vm:1: new (self)\n")


def test_measure_both_sides_alternately():
    """A short real run: two agents and ima-xch-bench, then ddsperf, without security and with
    it, twice."""
    told = []
    r = bench.measure(samples=20, repeats=2, progress=told.append, ddsperf_seconds=2)
    assert [t[:5] for t in told] == ["[1/2]"] * 4 + ["[2/2]"] * 4
    assert ["DDS Security" in t for t in told] == [False, False, True, True] * 2
    assert len(r["repeats"]) == 2
    # node1's agent takes node2's inputs of every round, warm-up included
    assert r["dds_latency_samples"] == 2 * (20 + 50)
    assert r["xch_latency_samples"] == 2 * 20 and r["xch_latency_incomplete"] == 0
    assert 0 < r["dds_latency_us_min"] <= r["dds_latency_us_median"] <= r["dds_latency_us_p95"]
    assert 0 < r["xch_latency_us_min"] <= r["xch_latency_us_median"] <= r["xch_latency_us_p95"]
    assert r["ddsperf_samples"] > 0 and r["ddsperf_latency_us_median"] > 0
    assert r["ratio"] == round(r["dds_latency_us_median"] / r["ddsperf_latency_us_median"], 2)
    assert r["xch_ratio"] == round(r["xch_latency_us_median"] / r["ddsperf_latency_us_median"],
                                   2)
    # the same with DDS Security, ddsperf under the same governance
    assert r["security"] == "sign"
    assert r["dds_latency_secure_us_median"] > 0 and r["ddsperf_secure_latency_us_median"] > 0
    assert r["secure_ratio"] == round(r["dds_latency_secure_us_median"]
                                      / r["ddsperf_secure_latency_us_median"], 2)


def test_measure_refuses_nothing_to_measure():
    with pytest.raises(ImaError):
        bench.measure(samples=0)
