# SPDX-License-Identifier: Apache-2.0
"""The world's fault-spec parser against the grammar of faultinject/include/fi/spec.h: the
cases of faultinject/test/test_spec.c, with the same results and the same messages."""

from __future__ import annotations

import pytest

from imaworld.faultspec import NEVER, FaultSpecError, param_float, parse, parse_time


def test_permanent():
    s = parse("memory_violation:fid=f1,at=60s,process=nav_fcs")
    assert (s.cls, s.fid, s.at_ns, s.until_ns, s.duration) == \
        ("memory_violation", "f1", 60_000_000_000, NEVER, "permanent")
    assert s.params == {"process": "nav_fcs"}
    assert s.spell(59_999_999_999) == -1 and s.spell(60_000_000_000) == 0
    assert s.spell(1 << 62) == 0 and s.end() == NEVER
    assert s.next_change(0) == 60_000_000_000 and s.next_change(60_000_000_000) == NEVER


def test_transient_and_units():
    s = parse("can_drop:fid=x-2,from=1.5s,until=1600ms,id=0x8d80640")
    assert (s.at_ns, s.until_ns, s.duration) == (1_500_000_000, 1_600_000_000, "transient")
    assert s.spell(1_599_999_999) == 0 and s.spell(1_600_000_000) == -1
    assert s.params["id"] == "0x8d80640"
    assert s.next_change(1_500_000_000) == 1_600_000_000
    assert parse_time("250us") == 250_000 and parse_time("7") == 7 and parse_time("2.5ns") == 3
    assert parse_time("7 s") is None and parse_time("-1s") is None and parse_time("nan") is None
    assert parse_time("1h") is None and parse_time("1e20s") is None


def test_intermittent():
    s = parse("gps_loss:fid=g,at=10s,period=4s,on=1s,until=30s")
    assert s.duration == "intermittent"
    assert s.spell(10_000_000_000) == 0 and s.spell(10_999_999_999) == 0
    assert s.spell(11_000_000_000) == -1 and s.spell(14_500_000_000) == 1
    assert s.spell_start(2) == 18_000_000_000 and s.spell_end(2) == 19_000_000_000
    assert s.spell(30_000_000_000) == -1
    # every start and end, in order, then nothing: the spells the injector acts on
    t, changes = -1, []
    while (t := s.next_change(t)) != NEVER:
        changes.append((t // 1_000_000_000, s.spell(t)))
    assert changes == [(10, 0), (11, -1), (14, 1), (15, -1), (18, 2), (19, -1), (22, 3),
                       (23, -1), (26, 4), (27, -1)]
    assert param_float(s, "value", 0.5) == 0.5


def test_back_to_back_spells_and_an_end_inside_a_spell():
    s = parse("x:fid=a,at=1s,period=2s,on=2s,until=4500ms")
    assert [s.next_change(t) for t in (0, 1_000_000_000, 3_000_000_000)] == \
        [1_000_000_000, 3_000_000_000, 4_500_000_000]
    assert s.spell(3_000_000_000) == 1 and s.spell_end(1) == 4_500_000_000


@pytest.mark.parametrize("spec, says", [
    ("Memory:fid=a,at=1s", "a fault class"),
    ("crash:at=1s", "fid=ID is required"),
    ("crash:fid=a", "at=TIME is required"),
    ("crash", "fid=ID is required"),
    ("crash:fid=a b,at=1s", "fid 'a b'"),
    ("crash:fid=0123456789abcdef,at=1s", "fid '0123456789abcdef'"),
    ("crash:fid=a,at=2s,until=1s", "until must be after at"),
    ("crash:fid=a,at=1s,period=1s", "both period and on"),
    ("crash:fid=a,at=1s,period=1s,on=2s", "0 < on <= period"),
    ("crash:fid=a,at=1h", "bad time '1h' for 'at'"),
    ("crash:fid=a,at=1s,x", "'x': expected KEY=VALUE"),
    ("crash:fid=a,at=1s,k=1,k=2", "given twice"),
    ("crash:fid=a,at=1s,=1", "parameter '' too long or empty"),
    ("crash:fid=a,at=1s," + ",".join(f"k{i}=1" for i in range(13)), "more than 12 parameters"),
    ("c:fid=a,at=1s,k=" + "v" * 1100, "longer than 1023 characters"),
])
def test_refused(spec, says):
    with pytest.raises(FaultSpecError) as e:
        parse(spec)
    assert says in str(e.value) and e.value.exit_code == 2 and "\n" not in str(e.value)


def test_empty_fields_are_skipped_and_a_value_may_hold_equals_signs():
    s = parse("c:fid=a,,at=1s,,k=a=b,")
    assert s.at_ns == 1_000_000_000 and s.params == {"k": "a=b"}


def test_a_parameter_that_is_not_a_number():
    s = parse("ahrs_bias:fid=a,at=1s,value=lots")
    with pytest.raises(FaultSpecError, match="value=lots is not a number"):
        param_float(s, "value")
    assert param_float(parse("a:fid=a,at=0,v=-2.5e1"), "v") == -25.0
