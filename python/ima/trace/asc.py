# SPDX-License-Identifier: Apache-2.0
"""The classic CAN frames of a Vector ASC log, scanned whole by regular expressions (about
three times python-can's ASCReader, which builds a Message per line).

Only the common case is read here: a log whose header says `base hex` and absolute time
stamps, with data frames (`d`), remote frames (`r`) and error frames (`ErrorFrame`) of
classic CAN. Every line python-can would take for a message must be one of those, or None is
returned and the caller reads the log with python-can: a log in decimal, with relative time
stamps, CAN FD frames or frame attributes after the data. Times are exact: the decimal time
stamp in ns, from the first frame's."""

from __future__ import annotations

import re
from binascii import unhexlify
from pathlib import Path

_BASE = re.compile(rb"^[ \t]*base[ \t]+(hex|dec)(?:[ \t]+timestamps[ \t]+(absolute|relative))?",
                   re.M | re.I)
# the lines python-can's reader takes for messages (its ASC_MESSAGE_REGEX, at a line's start)
_MESSAGE = re.compile(
    rb"^[ \t]*\d+\.\d+\s+(?:\d+\s+(?:\w+\s+(?:Tx|Rx)|ErrorFrame)|CANFD)", re.M)
# a frame line in one alternation, found from the newline before it (a fast literal search):
# time (seconds, fraction), then an identifier (hex, x: 29-bit), its direction, and a data
# frame's DLC and bytes, or `r` (a remote frame); or ErrorFrame
_FRAME = re.compile(
    rb"\n[ \t]*(\d+)\.(\d+)[ \t]+\d+[ \t]+(?:([0-9A-Fa-f]+)(x?)[ \t]+(?:Rx|Tx)[ \t]+"
    rb"(?:d[ \t]+([0-8])((?:[ \t]+[0-9A-Fa-f]{2})*)|(r)(?:[ \t]+\d+)?)|(ErrorFrame))"
    rb"[ \t]*(?=\r?\n)")


def _ns(sec: bytes, frac: bytes) -> int:
    return int(sec) * 1_000_000_000 + int((frac + b"000000000")[:9])


def read(path: Path):
    """(times ns, identifiers, extended, remote, error, data) lists in the log's order; None
    if python-can must read the file."""
    text = b"\n" + Path(path).read_bytes() + b"\n"
    base = _BASE.search(text)
    if base is None or base.group(1).lower() != b"hex" or (
            base.group(2) or b"absolute").lower() != b"absolute":
        return None
    found = _FRAME.findall(text)
    if len(found) != len(_MESSAGE.findall(text)):
        return None  # lines this reader does not know: python-can reads them
    t = [int(sec) * 1_000_000_000 + int((frac + b"000000000")[:9])
         for sec, frac, *_ in found]
    # an error frame is python-can's default message: identifier 0, 29-bit
    ids = [int(f[2], 16) if f[2] else 0 for f in found]
    ext = [f[3] == b"x" or f[7] != b"" for f in found]
    rtr = [f[6] != b"" for f in found]
    err = [f[7] != b"" for f in found]
    data = [unhexlify(f[5].replace(b" ", b"").replace(b"\t", b"")) if f[4] else b""
            for f in found]
    if any(len(d) != int(f[4]) for d, f in zip(data, found, strict=True) if f[4]):
        return None  # fewer bytes than the DLC says: python-can decides
    return t, ids, ext, rtr, err, data
