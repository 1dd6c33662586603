# SPDX-License-Identifier: Apache-2.0
"""The fast codecs agree with cantools on every message of rpas.dbc, both ways; what cantools
read of a DBC is kept and read back the same."""

from __future__ import annotations

import json
import random

import cantools
import pytest

from ima.canbus import codec, dbc_table

DB = cantools.database.load_file(str(codec.DBC_PATH))
NAMES = sorted(m.name for m in DB.messages)


def test_every_dbc_message_has_a_codec():
    assert sorted(codec.MESSAGES) == NAMES
    for m in DB.messages:
        c = codec.MESSAGES[m.name]
        assert (c.frame_id, c.extended, c.length) == (m.frame_id, m.is_extended_frame, m.length)
        assert codec.BY_ID[m.frame_id] is c


def _raw_range(s):
    if s.is_signed:
        return -(1 << (s.length - 1)), (1 << (s.length - 1)) - 1
    return 0, (1 << s.length) - 1


@pytest.mark.parametrize("name", NAMES)
def test_encode_matches_cantools(name):
    rng = random.Random(name)
    m, c = DB.get_message_by_name(name), codec.MESSAGES[name]
    for _ in range(300):
        values = {}
        for s in m.signals:
            lo, hi = _raw_range(s)
            lo_phys, hi_phys = lo * s.scale + s.offset, hi * s.scale + s.offset
            if s.minimum is not None:
                lo_phys = max(lo_phys, s.minimum)
            if s.maximum is not None:
                hi_phys = min(hi_phys, s.maximum)
            v = rng.uniform(lo_phys, hi_phys)
            values[s.name] = round(v) if s.scale == 1 else v
        assert c.encode_dict(values) == m.encode(values, strict=False), values


@pytest.mark.parametrize("name", NAMES)
def test_decode_matches_cantools(name):
    rng = random.Random(name + "/decode")
    m, c = DB.get_message_by_name(name), codec.MESSAGES[name]
    for _ in range(300):
        data = bytes(rng.getrandbits(8) for _ in range(m.length))
        ours = c.decode_dict(data)
        theirs = m.decode(data, decode_choices=False, scaling=True)
        assert ours.keys() == theirs.keys()
        for k in ours:
            assert ours[k] == pytest.approx(theirs[k], rel=1e-12, abs=1e-12), (k, data.hex())


def test_encode_saturates_out_of_range_values():
    c = codec.MESSAGES["AHRS_ATT"]
    roll, pitch, hdg, stat, cnt = c.decode(c.encode(400.0, -400.0, 1000.0, 3, 300))
    assert roll == pytest.approx(327.67) and pitch == pytest.approx(-327.68)
    assert hdg == pytest.approx(655.35) and cnt == 255


def test_roundtrip_keeps_resolution():
    c = codec.MESSAGES["GPS_POS"]
    lat, lon = c.decode(c.encode(47.1234567, -8.7654321))
    assert lat == pytest.approx(47.1234567, abs=1e-7) and lon == pytest.approx(-8.7654321, abs=1e-7)


def test_choices_come_from_the_dbc():
    assert codec.choices("FCS_STATUS_A", "FCS_MODE_A")[2] == "AUTOPILOT"


def _layouts(messages: dict) -> dict:
    return {n: (m.frame_id, m.extended, m.length, m.cycle_ms, m.signals)
            for n, m in messages.items()}


def test_the_dbc_cache_gives_the_same_codecs_and_follows_the_file(tmp_path, monkeypatch):
    """What cantools read of a DBC is kept in the build tree by the file's content: a second
    load reads the cache (not cantools), the same layouts; a changed file is read anew; a
    garbled cache is read around and written again."""
    monkeypatch.setenv("IMA_BUILD_DIR", str(tmp_path / "build"))
    (tmp_path / "build").mkdir()
    dbc = tmp_path / "a.dbc"
    dbc.write_bytes(codec.DBC_PATH.read_bytes())
    first = codec.load(dbc)
    (cache,) = (tmp_path / "build" / "dbc-cache").iterdir()
    assert _layouts(first) == _layouts(codec.MESSAGES)
    calls = []
    monkeypatch.setattr(dbc_table, "_read", lambda p: calls.append(p) or [])
    assert _layouts(codec.load(dbc)) == _layouts(first) and calls == []  # from the cache
    m = first["AHRS_ATT"]
    data = m.encode(12.5, -3.25, 271.0, 3, 7)
    assert codec.load(dbc)["AHRS_ATT"].decode(data) == m.decode(data)
    dbc.write_bytes(codec.DBC_PATH.read_bytes() + b"\n")  # another file: another key
    assert codec.load(dbc) == {} and calls == [dbc]
    monkeypatch.undo()
    monkeypatch.setenv("IMA_BUILD_DIR", str(tmp_path / "build"))
    cache.write_text("{not json")
    dbc.write_bytes(codec.DBC_PATH.read_bytes())
    assert _layouts(codec.load(dbc)) == _layouts(first)
    assert json.loads(cache.read_text())["layout"] == dbc_table.LAYOUT


def test_the_cache_key_has_the_version_of_cantools_that_importlib_metadata_gives(monkeypatch):
    from importlib import metadata

    version = metadata.version("cantools")
    assert dbc_table._cantools_version() == version

    def refuse(name):  # the version comes from the distribution's directory name
        raise AssertionError(f"importlib.metadata asked for {name}")

    monkeypatch.setattr(metadata, "version", refuse)
    assert dbc_table._cantools_version() == version


def test_a_signal_the_fast_codec_cannot_decode_is_refused_by_it_not_by_the_table(tmp_path,
                                                                                  monkeypatch):
    """The deployment reads any DBC's messages through the cache; the fast codec refuses a
    big-endian signal when it is built."""
    monkeypatch.setenv("IMA_BUILD_DIR", str(tmp_path / "build"))
    (tmp_path / "build").mkdir()
    dbc = tmp_path / "motorola.dbc"
    dbc.write_text('VERSION ""\n\nBU_: A\n\nBO_ 291 M: 8 A\n'
                   ' SG_ LE : 0|8@1+ (1,0) [0|255] "" A\n'
                   ' SG_ BE : 15|8@0+ (1,0) [0|255] "" A\n')
    for _ in range(2):  # read, then from the cache
        (m,) = dbc_table.table(dbc)
        assert (m["name"], m["frame_id"], m["unsupported"]) == ("M", 291, "M.BE")
    with pytest.raises(ValueError, match="M.BE"):
        codec.load(dbc)
