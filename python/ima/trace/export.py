# SPDX-License-Identifier: Apache-2.0
"""`ima trace export INPUT --format F -o FILE`: the frames in a format other CAN tools read,
written by python-can's own writers: asc (Vector ASCII), blf (Vector binary), log (candump),
trc (PEAK), csv. Time stamps are the run's emulated time (a reader may count them from the
first frame). Every frame goes on channel 0 (one bus). A frame a format cannot carry (error
and remote frames in TRC) is counted and reported, never dropped silently; an error frame
carries no identifier, and a candump log keeps no DLC of a remote frame."""

from __future__ import annotations

import json
from pathlib import Path

from ima.errors import ImaError

FORMATS = ("asc", "blf", "log", "trc", "csv")
# frame kinds python-can's writer and reader of a format cannot carry through (measured by
# tests/trace/test_trace_export.py): they are counted, not written
CANNOT = {"trc": {"error", "remote"}}
# what a format keeps of a remote frame's DLC (candump's "#R" has none)
REMOTE_DLC = {"asc": True, "blf": True, "log": False, "trc": False, "csv": True}


def _message(f):
    import can

    return can.Message(timestamp=f.t_ns / 1e9, arbitration_id=f.id, is_extended_id=f.extended,
                       is_remote_frame=f.remote, is_error_frame=f.error,
                       dlc=(f.dlc if f.dlc >= 0 else len(f.data)),
                       data=None if (f.remote or f.error) else f.data, channel=0)


def _writer(fmt: str, path: Path):
    import can

    cls = {"asc": can.ASCWriter, "blf": can.BLFWriter, "log": can.CanutilsLogWriter,
           "trc": can.TRCWriter, "csv": can.CSVWriter}[fmt]
    return cls(str(path))


def export(frames: list, fmt: str, path: Path) -> dict:
    """Writes the frames; returns {"written", "skipped": {kind: count}}."""
    if fmt not in FORMATS:
        raise ImaError(f"--format {fmt!r}: one of {', '.join(FORMATS)}")
    skipped: dict[str, int] = {}
    written = 0
    try:
        with _writer(fmt, path) as w:
            for f in frames:
                kind = "error" if f.error else "remote" if f.remote else "data"
                if kind in CANNOT.get(fmt, ()):
                    skipped[kind] = skipped.get(kind, 0) + 1
                    continue
                w.on_message_received(_message(f))
                written += 1
    except OSError as e:
        raise ImaError(f"{path}: cannot write: {e.strerror}") from e
    return {"format": fmt, "file": str(path), "written": written, "skipped": skipped}


def add_arguments(p) -> None:
    p.add_argument("input", type=Path, metavar="INPUT", help="a run directory or a log")
    p.add_argument("--format", required=True, choices=FORMATS, help="the log format")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="FILE",
                   help="the file to write")
    p.add_argument("--json", action="store_true", help="the counts as one JSON object")


def run(args) -> int:
    from ima import outdir
    from ima.trace import source

    out = args.output
    if out.is_dir():
        raise ImaError(f"{out} is a directory: give the file to write")
    outdir.usable_dir(out.parent if str(out.parent) else Path("."), "the output's folder")
    trace = source.load(args.input)
    r = export(trace.frames, args.format, out)
    if args.json:
        print(json.dumps(r))
    else:
        skipped = ", ".join(f"{n} {k} frames" for k, n in r["skipped"].items())
        print(f"{out}: {r['written']} frames" + (f"; not written ({args.format} cannot carry "
                                                f"them): {skipped}" if skipped else ""))
    return 0
