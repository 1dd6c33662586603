# SPDX-License-Identifier: Apache-2.0
"""The plan's image: what encode writes is what the C header declares (sizes, offsets and
constants, checked by compiling a program against partitions/include/rpas/mission_plan.h),
decode reads it back, and the C CRC of an image is zlib's."""

from __future__ import annotations

import math
import shutil
import struct
import subprocess

import pytest

from ima.mission import image, plan

from .conftest import MISSIONS, ROOT

STRUCTS = {"rpas_plan_header_t": image.HEADER_FIELDS, "rpas_plan_leg_t": image.LEG_FIELDS,
           "rpas_plan_contingency_t": image.CONTINGENCY_FIELDS}


def _constants() -> dict[str, int]:
    out = {"RPAS_PLAN_MAGIC": image.PLAN_MAGIC, "RPAS_PLAN_VERSION": image.PLAN_VERSION,
           "RPAS_PLAN_MAX_LEGS": image.PLAN_MAX_LEGS, "RPAS_CT_COUNT": image.CT_COUNT}
    out |= {f"RPAS_LEG_{k}": v for k, v in image.LEG_TYPES.items()}
    out |= {f"RPAS_LEG_{k}": v for k, v in image.LEG_FLAGS.items()}
    out |= {f"RPAS_CT_{k}": v for k, v in image.CONTINGENCY_CODES.items()}
    out |= {f"RPAS_CTA_{k}": v for k, v in image.ACTION_CODES.items()}
    return out


def _program() -> str:
    lines = ["#include <stdio.h>", "#include <stdlib.h>", '#include "rpas/mission_plan.h"',
             "int main(int argc, char **argv) {"]
    for s, fields in STRUCTS.items():
        lines.append(f'    printf("{s} %zu\\n", sizeof({s}));')
        for name, _ in fields:
            lines.append(f'    printf("{s}.{name} %zu %zu\\n", offsetof({s}, {name}), '
                         f"sizeof((({s} *)0)->{name}));")
    for name in _constants():
        lines.append(f'    printf("{name} %llu\\n", (unsigned long long)({name}));')
    lines += ["    FILE *f = fopen(argv[1], \"rb\");",
              "    static unsigned char buf[RPAS_PLAN_MAX_BYTES];",
              "    size_t n = fread(buf, 1, sizeof buf, f);",
              "    fclose(f);",
              '    printf("crc %u %zu\\n", rpas_crc32(buf, n), n);',
              "    return argc > 1 ? 0 : 1;", "}"]
    return "\n".join(lines) + "\n"


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler (cc)")
def test_image_layout(tmp_path):
    src, exe, img = tmp_path / "layout.c", tmp_path / "layout", tmp_path / "legs.img"
    src.write_text(_program())
    subprocess.run(["cc", "-std=c11", "-Wall", "-Werror", f"-I{ROOT / 'partitions/include'}",
                    "-o", str(exe), str(src)], check=True, capture_output=True, timeout=60)
    data = image.encode(plan.load(MISSIONS / "legs.yaml"))
    img.write_bytes(data)
    out = subprocess.run([str(exe), str(img)], check=True, capture_output=True, text=True,
                         timeout=30).stdout
    c = {}
    for line in out.splitlines():
        key, *values = line.split()
        c[key] = tuple(int(v) for v in values)
    assert c["rpas_plan_header_t"] == (image.HEADER.size,) == (200,)
    assert c["rpas_plan_leg_t"] == (image.LEG.size,) == (48,)
    assert c["rpas_plan_contingency_t"] == (image.CONTINGENCY.size,) == (24,)
    for s, fields in STRUCTS.items():
        for name, where in image.layout(fields).items():
            assert c[f"{s}.{name}"] == where, f"{s}.{name}"
    for name, value in _constants().items():
        assert c[name] == (value,), name
    assert c["crc"] == (image.crc32(data), len(data))


def test_round_trip():
    p = plan.load(MISSIONS / "legs.yaml")
    data = image.encode(p)
    d = image.decode(data)
    legs = p.image_legs()
    assert len(data) == 200 + 48 * len(legs)
    assert (d["magic"], d["version"], d["n_legs"], d["n_mission_legs"], d["plan_id"]) == (
        image.PLAN_MAGIC, 1, len(legs), len(p.legs), 2)
    assert data[:4] == b"MPLN"
    assert (d["origin_lat_e7"], d["origin_lon_e7"]) == (470000000, 80000000)
    assert (d["cruise_ias_kt"], d["cruise_alt_ft"], d["min_ias_kt"], d["max_ias_kt"],
            d["max_bank_deg"], d["max_vs_fpm"], d["traffic_h_m"], d["traffic_v_ft"]) == (
        100, 3000, 65, 125, 25, 800, 1000, 500)
    assert [x["type_name"] for x in d["legs"]] == [leg.type for leg, _ in legs]
    for x, (leg, _) in zip(d["legs"], legs, strict=True):
        if leg.fix:
            w = p.waypoints[leg.fix]
            assert (x["lat_e7"], x["lon_e7"]) == (round(w.lat_deg * 1e7), round(w.lon_deg * 1e7))
        assert (x["alt_ft"] == leg.altitude_ft) or (
            math.isnan(x["alt_ft"]) and leg.altitude_ft is None) or leg.type == "AUTOLAND"
    by = {i: x for i, x in enumerate(d["legs"])}
    assert by[1]["flags"] == image.LEG_FLAGS["FLY_OVER"] and by[1]["ias_kt"] == 95
    rf = by[2]
    cc = p.waypoints["CC"]
    assert (rf["lat2_e7"], rf["lon2_e7"]) == (round(cc.lat_deg * 1e7), round(cc.lon_deg * 1e7))
    assert rf["flags"] == image.LEG_FLAGS["TURN_RIGHT"] and math.isnan(rf["course_deg"])
    assert by[3]["flags"] == image.LEG_FLAGS["ALT_PATH"] and by[3]["course_deg"] == 180
    assert (by[6]["course_deg"], by[6]["alt_ft"], by[6]["lat_e7"]) == (0, 4000, 0)  # VA
    assert (by[9]["flags"], by[9]["a"], by[9]["count"]) == (image.LEG_FLAGS["TURN_LEFT"], 30, 0)
    assert (by[10]["count"], by[10]["a"], by[10]["course_deg"]) == (1, 40, 90)  # HM
    assert (by[11]["a"], by[11]["b"], by[11]["count"]) == (800, 0, 1)  # ORBIT, laps
    assert (by[15]["a"], by[15]["b"], by[15]["count"]) == (900, 120, 0)  # ORBIT, time
    scan = by[12]
    assert (scan["course_deg"], scan["a"], scan["b"], scan["count"], scan["flags"]) == (
        180, 2000, 600, 3, image.LEG_FLAGS["TURN_LEFT"])
    assert (by[13]["course_deg"], by[13]["a"]) == (180, 800)  # DUBINS
    land = by[17]
    assert (land["course_deg"], land["alt_ft"], land["a"], land["b"], land["c"], land["d"]) == (
        0, 500, 3, 300, 1200, 30)
    assert math.isnan(land["ias_kt"])
    ct = {c["name"]: c for c in d["contingency"]}
    assert [c["name"] for c in d["contingency"]] == list(plan.CONTINGENCIES)
    assert (ct["c2_loss"]["action_name"], ct["c2_loss"]["first_leg"], ct["c2_loss"]["n_legs"],
            ct["c2_loss"]["resume"], ct["c2_loss"]["continue_s"]) == ("procedure", 18, 2, 1, 10)
    assert (ct["autopilot_disengage"]["first_leg"], ct["autopilot_disengage"]["n_legs"]) == (
        20, 2)
    assert [x["type_name"] for x in d["legs"][18:]] == ["DIRECT", "HM", "VA", "ORBIT"]
    assert (ct["traffic"]["action_name"], ct["traffic"]["p1"], ct["traffic"]["p2"]) == (
        "avoid", 45, 300)
    assert ct["traffic"]["continue_s"] == 0.0  # no procedure to wait for
    assert (ct["gps_loss"]["action_name"], ct["gps_loss"]["n_legs"]) == ("hold", 0)
    assert ct["flight_termination"]["action_name"] == "terminate"
    assert all(math.isnan(v) for v in d["pad"])


def test_an_undeclared_contingency_is_none(doc):
    d = image.decode(image.encode(plan.parse(doc, "x.yaml")))
    gps = d["contingency"][1]
    assert (gps["name"], gps["action"], gps["n_legs"]) == ("gps_loss", 0, 0)
    assert gps["detect_s"] == 0.0
    hm = d["legs"][2]
    assert (hm["flags"], hm["count"], hm["a"]) == (image.LEG_FLAGS["TURN_RIGHT"], 1, 60)


@pytest.mark.parametrize(("mangle", "expected"), [
    (lambda b: b[:100], "shorter than the 200-byte header"),
    (lambda b: b"XXXX" + b[4:], "magic 0x58585858"),
    (lambda b: b[:4] + struct.pack("<H", 2) + b[6:], "version 2"),
    (lambda b: b[:-1], "for 5 legs"),
])
def test_decode_refuses_what_is_not_an_image(doc, mangle, expected):
    data = image.encode(plan.parse(doc, "x.yaml"))
    with pytest.raises(ValueError, match=expected):
        image.decode(mangle(data))
