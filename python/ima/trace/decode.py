# SPDX-License-Identifier: Apache-2.0
"""Decoding frames with a DBC: the product's fast generated codecs (ima.canbus.codec) when
the DBC's signals allow them, cantools otherwise."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ima.errors import ImaError


class Decoder:
    """name_of(id) and decode(id, data) -> {signal: value} for the messages of a DBC."""

    def __init__(self, dbc: Path | None = None) -> None:
        from ima.canbus import codec

        path = Path(dbc) if dbc else codec.DBC_PATH
        self._names: dict[int, str] = {}
        self._decode: dict[int, Callable[[bytes], dict]] = {}
        self.cycle_ms: dict[str, int | None] = {}
        self.signals: dict[str, tuple[str, ...]] = {}
        try:
            messages = codec.MESSAGES if dbc is None else codec.load(path)
            for m in messages.values():
                self._add(m.frame_id, m.name, m.decode_dict, m.cycle_ms, m.signal_names)
        except ValueError:  # signals the fast codec does not handle: cantools for all
            import cantools

            try:
                db = cantools.database.load_file(str(path), strict=False)
            except Exception as e:  # noqa: BLE001 - cantools raises per format
                raise ImaError(f"{path}: cannot read the DBC: {e}") from e
            for m in db.messages:
                self._add(m.frame_id, m.name, lambda d, m=m: m.decode(d, decode_choices=False),
                          m.cycle_time or None, tuple(s.name for s in m.signals))
        except OSError as e:
            raise ImaError(f"{path}: cannot read the DBC: {e.strerror}") from e
        self.path = path

    def _add(self, frame_id, name, dec, cycle, signals) -> None:
        self._names[frame_id] = name
        self._decode[frame_id] = dec
        self.cycle_ms[name] = cycle
        self.signals[name] = tuple(signals)

    def id_of(self, name: str) -> int | None:
        return next((i for i, n in self._names.items() if n == name), None)

    def name_of(self, frame_id: int) -> str | None:
        return self._names.get(frame_id)

    def decode(self, frame_id: int, data: bytes) -> dict | None:
        dec = self._decode.get(frame_id)
        if dec is None:
            return None
        try:
            return dec(bytes(data))
        except Exception:  # noqa: BLE001 - a frame shorter than its message: not decodable
            return None
