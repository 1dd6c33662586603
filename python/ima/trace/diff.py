# SPDX-License-Identifier: Apache-2.0
"""`ima trace diff A B`: the first frame at which two runs' CAN traffic diverge.

Both traces are read in bus order (time, then identifier). The first position where the
frames differ — in time, identifier, flags or data, or a frame one run has and the other
has not — is the divergence: its time, identifier, message and the decoded signals that
differ. Two runs of the same model and seed are bit-identical (lockstep emulated time), so
the divergence is where a fault, a change of code or of settings first showed on the bus.
"""

from __future__ import annotations

import json
from pathlib import Path


def _key(f) -> tuple:
    return (f.t_ns, f.id, f.extended, f.remote, f.error, f.data)


def first_divergence(a: list, b: list, decoder=None) -> dict | None:
    fa = sorted(a, key=lambda f: (f.t_ns, f.id, f.data))
    fb = sorted(b, key=lambda f: (f.t_ns, f.id, f.data))
    n = min(len(fa), len(fb))
    i = next((k for k in range(n) if _key(fa[k]) != _key(fb[k])), n)
    if i == len(fa) == len(fb):
        return None
    x = fa[i] if i < len(fa) else None
    y = fb[i] if i < len(fb) else None
    # the earlier of the two is where they part
    first = x if y is None or (x is not None and (x.t_ns, x.id) <= (y.t_ns, y.id)) else y
    name = decoder.name_of(first.id) if decoder else None
    out = {"index": i, "t_s": round(first.t_ns / 1e9, 6), "id": first.id,
           "hex": f"0x{first.id:08X}" if first.extended else f"0x{first.id:03X}",
           "name": name, "a": _frame(x), "b": _frame(y), "signals": []}
    if decoder and x is not None and y is not None and x.id == y.id:
        da, db = decoder.decode(x.id, x.data) or {}, decoder.decode(y.id, y.data) or {}
        out["signals"] = [{"signal": s, "a": da.get(s), "b": db.get(s)}
                          for s in da if da.get(s) != db.get(s)]
    return out


def _frame(f) -> dict | None:
    if f is None:
        return None
    return {"t_s": round(f.t_ns / 1e9, 6), "id": f.id, "data": f.data.hex(),
            "sender": f.sender or None}


# ---- the subcommand ---------------------------------------------------------------------

def add_arguments(p) -> None:
    p.add_argument("a", type=Path, metavar="A", help="a run directory or a log")
    p.add_argument("b", type=Path, metavar="B", help="the other")
    p.add_argument("--dbc", type=Path, metavar="FILE", help="default config/can/rpas.dbc")
    p.add_argument("--json", action="store_true", help="the result as one JSON object")


def run(args) -> int:
    from ima.trace import source
    from ima.trace.decode import Decoder

    ta, tb = source.load(args.a), source.load(args.b)
    d = first_divergence(ta.frames, tb.frames, Decoder(args.dbc))
    result = {"a": ta.source, "b": tb.source, "frames_a": len(ta.frames),
              "frames_b": len(tb.frames), "first_divergence": d}
    if args.json:
        print(json.dumps(result))
        return 0
    if d is None:
        print(f"identical: {len(ta.frames)} frames in both")
        return 0
    what = d["name"] or d["hex"]
    print(f"first divergence at {d['t_s']:.6f} s, frame {d['index']}: {what} ({d['hex']})")
    for side in ("a", "b"):
        f = d[side]
        src = ta.source if side == "a" else tb.source
        print(f"  {side.upper()} {src}: " + ("no frame" if f is None else
              f"{f['t_s']:.6f} s id 0x{f['id']:X} data {f['data']}"
              + (f" from {f['sender']}" if f["sender"] else "")))
    for s in d["signals"]:
        print(f"  {s['signal']}: {s['a']} | {s['b']}")
    return 0
