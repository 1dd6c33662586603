# SPDX-License-Identifier: Apache-2.0
"""python-can on the live bus: `python -m can.logger -i ima` records a real-time flight,
every frame of its log decodes with the DBC, and `ima trace stats` analyses the log."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import can
import cantools

ROOT = Path(__file__).resolve().parents[2]
DBC = ROOT / "config" / "can" / "rpas.dbc"


def test_can_logger_records_the_live_bus_and_the_log_decodes(tmp_path):
    run_dir = tmp_path / "run"
    log = tmp_path / "bus.asc"
    flight = subprocess.Popen(
        [sys.executable, "-m", "ima", "fly", "--realtime", "--duration", "6", "--run-dir",
         str(run_dir), "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        sock = run_dir / "can.sock"
        deadline = time.monotonic() + 30
        while not sock.exists():
            assert flight.poll() is None, flight.communicate()
            assert time.monotonic() < deadline, "the bus socket never appeared"
            time.sleep(0.02)
        logger = subprocess.run(
            [sys.executable, "-m", "can.logger", "-i", "ima", "-c", str(sock), "-f", str(log),
             "--bus-kwargs", "end_on_stop=True"], capture_output=True, text=True, timeout=60)
        assert "ended the run" in logger.stderr, logger.stderr[-2000:]
    finally:
        out, err = flight.communicate(timeout=60)
    assert flight.returncode == 0, err.decode()[-2000:]

    db = cantools.database.load_file(DBC)
    seen = Counter()
    with can.LogReader(str(log)) as reader:
        for msg in reader:
            assert msg.is_extended_id
            decoded = db.decode_message(msg.arbitration_id, msg.data)
            assert decoded, msg
            seen[db.get_message_by_frame_id(msg.arbitration_id).name] += 1
    # about 5 s of a 6 s flight: AHRS at 50 Hz, GPS at 5 Hz, the FCS's commands at 20 Hz
    assert seen["AHRS_ATT"] > 150, seen
    assert seen["GPS_POS"] > 15, seen
    assert seen["ACT_CMD_A"] > 60, seen
    assert seen["FCS_STATUS_A"] > 60, seen
    assert {"AIR_DATA", "ACT_STATUS", "PILOT_MODE", "PILOT_TARGETS", "NAV_POS_A"} <= set(seen)

    stats = subprocess.run([sys.executable, "-m", "ima", "trace", "stats", str(log), "--json"],
                           capture_output=True, text=True, timeout=120)
    assert stats.returncode == 0, stats.stderr
    r = json.loads(stats.stdout)
    assert r["frames"] == sum(seen.values()) and r["error_frames"] == 0
    by_name = {i["name"]: i for i in r["ids"]}
    assert by_name["AHRS_ATT"]["count"] == seen["AHRS_ATT"]
    assert 15 <= by_name["AHRS_ATT"]["period_ms_p50"] <= 25  # 50 Hz, on the wall clock
    assert 0 < r["bus_load"] < r["bus_load_worst_case"]
