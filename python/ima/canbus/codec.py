# SPDX-License-Identifier: Apache-2.0
"""Fast CAN codecs for the messages of config/can/rpas.dbc, generated from the DBC at import time.

cantools is the source of truth for every layout, but its encode/decode costs tens of
microseconds per frame; the world sends and receives a few hundred thousand frames per flight.
So, at import, each message's signals are turned into one small Python function doing plain
integer shifts (all our signals are little-endian), compiled once. A test checks every message
against cantools over random values. What cantools read of a DBC is kept in the build tree
(dbc_table.py), so that the processes of a run do not each import it.

Encoding rounds like cantools (round((value - offset) / scale)) and then saturates at the
raw range of the signal instead of failing: a sensor that reads past its field's range sends
the range's end. Decoding returns physical values as floats (ints for scale-1 signals).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

from ima.canbus import dbc_table

DBC_PATH = Path(__file__).resolve().parents[3] / "config" / "can" / "rpas.dbc"


@dataclasses.dataclass(frozen=True)
class SignalInfo:
    name: str
    start: int
    length: int
    signed: bool
    scale: float
    offset: float
    minimum: float | None
    maximum: float | None
    choices: dict[int, str]


@dataclasses.dataclass(frozen=True)
class MessageCodec:
    """One message: `encode(*values) -> bytes` (signals in DBC order), `decode(data) -> tuple`."""

    name: str
    frame_id: int  # without the extended flag
    extended: bool
    length: int
    cycle_ms: int | None
    signals: tuple[SignalInfo, ...]
    encode: Callable[..., bytes]
    decode: Callable[[bytes], tuple]

    @property
    def signal_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.signals)

    def encode_dict(self, values: dict) -> bytes:
        return self.encode(*(values[s.name] for s in self.signals))

    def decode_dict(self, data: bytes) -> dict:
        return dict(zip(self.signal_names, self.decode(data), strict=True))


def integral(x: float) -> bool:
    """Whether a scale or an offset is compiled as an integer literal: a signal whose scale and
    offset both are decodes to an integer."""
    return isinstance(x, int) or (x.is_integer() and abs(x) < 2**53)


def _num(x: float) -> str:
    """A literal that compiles to exactly `x` (repr round-trips floats)."""
    return repr(int(x)) if integral(x) else repr(x)


def _build(name: str, sigs: list[SignalInfo], length: int) -> tuple[Callable, Callable]:
    args = [f"v{i}" for i in range(len(sigs))]
    enc = [f"def encode({', '.join(args)}):", "    x = 0"]
    dec = ["def decode(data):", f"    x = _from_bytes(data[:{length}], 'little')"]
    outs = []
    for i, s in enumerate(sigs):
        mask = (1 << s.length) - 1
        lo, hi = (-(1 << (s.length - 1)), (1 << (s.length - 1)) - 1) if s.signed else (0, mask)
        if s.scale == 1 and s.offset == 0:
            conv = f"round(v{i})"
        else:
            conv = f"round((v{i} - {_num(s.offset)}) / {_num(s.scale)})"
        enc += [f"    r = {conv}",
                f"    if r < {lo}: r = {lo}",
                f"    elif r > {hi}: r = {hi}",
                f"    x |= (r & {mask}) << {s.start}"]
        dec.append(f"    r{i} = (x >> {s.start}) & {mask}")
        if s.signed:
            dec.append(f"    if r{i} & {1 << (s.length - 1)}: r{i} -= {1 << s.length}")
        if s.scale == 1 and s.offset == 0:
            outs.append(f"r{i}")
        else:
            outs.append(f"r{i} * {_num(s.scale)} + {_num(s.offset)}")
    enc.append(f"    return x.to_bytes({length}, 'little')")
    dec.append(f"    return ({', '.join(outs)},)")
    ns: dict = {"_from_bytes": int.from_bytes}
    exec(compile("\n".join(enc) + "\n" + "\n".join(dec) + "\n", f"<codec {name}>", "exec"), ns)
    return ns["encode"], ns["decode"]


def load(path: str | Path = DBC_PATH) -> dict[str, MessageCodec]:
    """Codecs for every message of a DBC file, by message name."""
    out: dict[str, MessageCodec] = {}
    for m in dbc_table.table(Path(path)):
        if m["unsupported"]:
            raise ValueError(f"{path}: {m['unsupported']}: only plain little-endian integer "
                             "signals are supported by the fast codec")
        # (JSON keeps the value tables' keys as strings)
        sigs = [SignalInfo(**{**s, "choices": {int(k): v for k, v in s["choices"].items()}})
                for s in m["signals"]]
        enc, dec = _build(m["name"], sigs, m["length"])
        out[m["name"]] = MessageCodec(m["name"], m["frame_id"], m["extended"], m["length"],
                                      m["cycle_ms"], tuple(sigs), enc, dec)
    return out


MESSAGES: dict[str, MessageCodec] = load()
BY_ID: dict[int, MessageCodec] = {m.frame_id: m for m in MESSAGES.values()}


def choices(message: str, signal: str) -> dict[int, str]:
    """The value table of one signal (e.g. FCS_MODE_A: {0: 'INIT', 1: 'DIRECT', ...})."""
    for s in MESSAGES[message].signals:
        if s.name == signal:
            return dict(s.choices)
    raise KeyError(f"{message}.{signal}")
