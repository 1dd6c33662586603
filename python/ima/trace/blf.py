# SPDX-License-Identifier: Apache-2.0
"""The classic CAN frames of a Vector BLF log, read straight into lists (about three times
python-can's BLFReader, which builds a Message per frame and times each with Decimal).

A BLF file is a header ("LOGG", its size), then objects ("LOBJ", header size and version,
object size, type), each padded to four bytes. The frames are inside LOG_CONTAINER objects
(type 10), whose contents, zlib-compressed or not, are one stream of inner objects that may
straddle containers. Inner objects read here: CAN_MESSAGE (1) and CAN_MESSAGE2 (86), and
CAN_ERROR_EXT (73); others are skipped as python-can skips them. A file holding CAN FD
objects (100, 101), or anything this reader does not expect, gives None: the caller then
reads it with python-can. Times are exact: the object's time stamp in units of 10 µs (flag
1) or 1 ns, from the file's start."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

_LOGG = struct.Struct("<4sI")            # signature, header size
_OBJ = struct.Struct("<4sHHII")          # signature, header size, version, size, type
_CONTAINER = struct.Struct("<H6xI4x")    # compression, uncompressed size
_V1 = struct.Struct("<IHHQ")             # flags, client, object version, time stamp
_V2 = struct.Struct("<IBxHQ8x")          # flags, time stamp status, version, time stamp
_MSG = struct.Struct("<HBBI8s")          # channel, flags, DLC, identifier, data
_ERR = struct.Struct("<HHIBBBxIIH2x8s")  # channel, length, flags, ECC, position, DLC, ...
_CAN_MESSAGE, _CONTAINER_TYPE, _CAN_ERROR_EXT, _CAN_MESSAGE2 = 1, 10, 73, 86
_CAN_FD = (100, 101)
_EXT, _REMOTE = 0x80000000, 0x80


def _stream(raw: bytes) -> bytes | None:
    """The inner objects of every container, one after the other."""
    sig, pos = _LOGG.unpack_from(raw, 0)
    if sig != b"LOGG":
        return None
    parts = []
    while pos + _OBJ.size <= len(raw):
        sig, _, _, size, kind = _OBJ.unpack_from(raw, pos)
        if sig != b"LOBJ" or size < _OBJ.size:
            return None
        body = raw[pos + _OBJ.size:pos + size]
        pos += size + size % 4
        if kind != _CONTAINER_TYPE:
            continue
        method, _ = _CONTAINER.unpack_from(body, 0)
        data = body[_CONTAINER.size:]
        if method == 2:
            try:
                data = zlib.decompress(data)
            except zlib.error:
                return None  # cut or damaged: python-can reads what it can
        elif method != 0:
            return None
        parts.append(data)
    return b"".join(parts)


def read(path: Path):
    """(times ns, identifiers, extended, remote, error, data) lists; None if python-can must
    read the file."""
    stream = _stream(Path(path).read_bytes())
    if stream is None:
        return None
    t, ids, ext, rtr, err, data = [], [], [], [], [], []
    n, p = len(stream), 0
    while True:
        p = stream.find(b"LOBJ", p, p + 8)  # past the previous object's padding
        if p < 0 or p + _OBJ.size > n:
            break
        _, _, version, size, kind = _OBJ.unpack_from(stream, p)
        nxt = p + size
        if size < _OBJ.size or nxt > n:
            break  # cut at the end of the log
        q = p + _OBJ.size
        if version == 1:
            flags, _, _, stamp = _V1.unpack_from(stream, q)
            q += _V1.size
        elif version == 2:
            flags, _, _, stamp = _V2.unpack_from(stream, q)
            q += _V2.size
        else:
            p = nxt
            continue
        if kind in (_CAN_MESSAGE, _CAN_MESSAGE2):
            _, fl, dlc, cid, payload = _MSG.unpack_from(stream, q)
            remote = bool(fl & _REMOTE)
            data.append(b"" if remote else payload[:dlc])
            rtr.append(remote)
            err.append(False)
        elif kind == _CAN_ERROR_EXT:
            cid = _ERR.unpack_from(stream, q)[7]
            data.append(b"")
            rtr.append(False)
            err.append(True)
        elif kind in _CAN_FD:
            return None
        else:
            p = nxt
            continue
        t.append(stamp * 10_000 if flags == 1 else stamp)
        ids.append(cid & 0x1FFFFFFF)
        ext.append(bool(cid & _EXT))
        p = nxt
    if p >= 0 and p < n and stream.find(b"LOBJ", p) >= 0:
        return None  # an object not where the stream says: let python-can judge it
    return t, ids, ext, rtr, err, data
