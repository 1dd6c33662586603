# SPDX-License-Identifier: Apache-2.0
"""The length on the wire of a classic CAN frame (ISO 11898-1), in bit times.

`frame_bits` builds the frame bit by bit (start of frame, arbitration, control, data, the
CRC-15 it computes) and counts the stuff bits the transmitter inserts after five equal bits
in a row, from the start of frame to the end of the CRC sequence; then the CRC delimiter,
the ACK slot and delimiter, the end of frame (7) and the intermission (3). `worst_case_bits`
is the bound every schedulability analysis uses (Davis, Burns, Bril and Lukkien, 2007):
g + 8n + 13 + floor((g + 8n - 1) / 4), g = 34 (11-bit identifier) or 54 (29-bit).
"""

from __future__ import annotations

from functools import lru_cache

_CRC15_POLY = 0x4599
_TAIL_BITS = 1 + 1 + 1 + 7 + 3  # CRC delimiter, ACK slot, ACK delimiter, EOF, intermission


def _bits(value: int, width: int) -> list[int]:
    return [(value >> (width - 1 - i)) & 1 for i in range(width)]


def crc15(bits: list[int]) -> int:
    """The CAN CRC-15 of a bit sequence (start of frame to the end of the data)."""
    crc = 0
    for b in bits:
        nxt = b ^ ((crc >> 14) & 1)
        crc = (crc << 1) & 0x7FFF
        if nxt:
            crc ^= _CRC15_POLY
    return crc


def unstuffed(can_id: int, extended: bool, data: bytes, remote: bool = False,
              dlc: int | None = None) -> list[int]:
    """The bits subject to stuffing: start of frame to the end of the CRC sequence."""
    dlc = len(data) if dlc is None else dlc
    if extended:
        head = ([0] + _bits(can_id >> 18, 11) + [1, 1] + _bits(can_id & 0x3FFFF, 18)
                + [1 if remote else 0, 0, 0])
    else:
        head = [0] + _bits(can_id, 11) + [1 if remote else 0, 0, 0]
    bits = head + _bits(dlc, 4)
    if not remote:
        for byte in data:
            bits += _bits(byte, 8)
    return bits + _bits(crc15(bits), 15)


def stuff_count(bits: list[int]) -> int:
    """The stuff bits a transmitter inserts in `bits`: after five equal bits in a row one of
    the other value, which then counts as the first of the next run."""
    count = 0
    carry = 0  # equal bits already counted when a run starts: 1 after a stuff bit of its value
    i, n = 0, len(bits)
    while i < n:
        b, j = bits[i], i
        while j < n and bits[j] == b:
            j += 1
        length, first = j - i, 5 - carry
        if length >= first:
            more = (length - first) // 5
            count += 1 + more
            # a stuff bit right at the end of the run has the next run's value
            carry = 1 if (length - first) % 5 == 0 else 0
        else:
            carry = 0
        i = j
    return count


@lru_cache(maxsize=65536)
def frame_bits(can_id: int, extended: bool, data: bytes, remote: bool = False) -> int:
    """Bit times of a data (or remote) frame on the bus, stuff bits and intermission included."""
    bits = unstuffed(can_id, extended, data, remote)
    return len(bits) + stuff_count(bits) + _TAIL_BITS


def worst_case_bits(extended: bool, length: int) -> int:
    """The bound on frame_bits over every identifier and data of that length."""
    g = 54 if extended else 34
    return g + 8 * length + 13 + (g + 8 * length - 1) // 4


def frame_bits_columns(ids, extended, remote, lens, data8):
    """frame_bits of many frames at once, given as columns: `lens` their data lengths (0 to 8),
    `data8` an (n, 8) uint8 array of their data. One pass per group of frames of the same
    layout (numpy), the CRC and the stuff bits a byte at a time from tables: the same numbers,
    a hundred times faster on long traces."""
    import numpy as np

    n = len(lens)
    out = np.zeros(n, dtype=np.int64)
    ids = np.asarray(ids, dtype=np.int64)
    ext = np.asarray(extended, dtype=bool)
    rtr = np.asarray(remote, dtype=bool)
    lens = np.asarray(lens, dtype=np.int64)
    for e in (False, True):
        for r in (False, True):
            layout = (ext == e) & (rtr == r)
            for length in np.unique(lens[layout]):
                sel = np.nonzero(layout & (lens == length))[0]
                out[sel] = _group_bits(ids[sel], e, r, int(length), data8[sel, :length], np)
    return out


def _group_bits(ids, ext: bool, remote: bool, length: int, raw, np):
    m = len(ids)

    def field(values, width):
        shifts = np.arange(width - 1, -1, -1, dtype=np.int64)
        return ((values[:, None] >> shifts) & 1).astype(np.uint8)

    zeros = np.zeros((m, 1), dtype=np.uint8)
    ones = np.ones((m, 1), dtype=np.uint8)
    r = ones if remote else zeros
    if ext:
        parts = [zeros, field(ids >> 18, 11), ones, ones, field(ids & 0x3FFFF, 18), r, zeros,
                 zeros]
    else:
        parts = [zeros, field(ids, 11), r, zeros, zeros]
    parts.append(field(np.full(m, length, dtype=np.int64), 4))
    if length and not remote:
        parts.append(np.unpackbits(np.ascontiguousarray(raw, dtype=np.uint8), axis=1))
    bits = np.concatenate(parts, axis=1)
    bits = np.concatenate([bits, field(_crc15_rows(bits, np), 15)], axis=1)
    return bits.shape[1] + _stuff_rows(bits, np) + _TAIL_BITS


def _crc15_table() -> list[int]:
    """The CRC-15 register after eight bits (a byte, first bit most significant) from the
    register holding that byte's value in its top eight bits."""
    return [crc15(_bits(byte, 8)) for byte in range(256)]


def _stuff_table() -> tuple[list[list[int]], list[list[int]]]:
    """For each state before a byte of the bit stream (0..9: the last bit's value times 5 plus
    the length of the run of equal bits so far minus 1; 10: at the start) and each byte: the
    state after it and the stuff bits inserted in it (stuff_count, eight bits at a time)."""
    nxt, cnt = [], []
    for state in range(11):
        row_n, row_c = [], []
        for byte in range(256):
            last, run = (state // 5, state % 5 + 1) if state < 10 else (-1, 0)
            count = 0
            for k in range(7, -1, -1):
                b = (byte >> k) & 1
                run = run + 1 if b == last else 1
                last = b
                if run == 5:  # a stuff bit of the other value: the first of the next run
                    count += 1
                    last, run = 1 - b, 1
            row_n.append(last * 5 + run - 1)
            row_c.append(count)
        nxt.append(row_n)
        cnt.append(row_c)
    return nxt, cnt


_TABLES: dict = {}


def _tables(np):
    if not _TABLES:
        nxt, cnt = _stuff_table()
        _TABLES.update(crc=np.array(_crc15_table(), dtype=np.int64),
                       next=np.array(nxt, dtype=np.int32), count=np.array(cnt, dtype=np.int32))
    return _TABLES


def _crc15_rows(bits, np):
    """crc15 of each row of a (m, n) 0/1 array: a byte at a time from a table, the last
    bits one by one."""
    t = _tables(np)["crc"]
    m, n = bits.shape
    full = n // 8
    packed = np.packbits(bits[:, :full * 8], axis=1).astype(np.int64)
    crc = np.zeros(m, dtype=np.int64)
    for j in range(full):
        crc = ((crc << 8) & 0x7FFF) ^ t[((crc >> 7) ^ packed[:, j]) & 0xFF]
    for k in range(full * 8, n):
        nxt = bits[:, k].astype(np.int64) ^ ((crc >> 14) & 1)
        crc = ((crc << 1) & 0x7FFF) ^ (nxt * _CRC15_POLY)
    return crc


def _stuff_rows(bits, np):
    """stuff_count of each row of a (m, n) 0/1 array: a byte at a time from a table, the last
    bits one by one."""
    t = _tables(np)
    m, n = bits.shape
    full = n // 8
    packed = np.packbits(bits[:, :full * 8], axis=1).astype(np.int32)
    nxt, cnt = t["next"].ravel(), t["count"].ravel()
    state = np.full(m, 10 * 256, dtype=np.int32)  # state * 256: the row of the tables
    count = np.zeros(m, dtype=np.int64)
    for j in range(full):
        idx = state + packed[:, j]
        count += cnt[idx]
        state = nxt[idx] * 256
    state //= 256
    last = np.where(state < 10, state // 5, -1)
    run = np.where(state < 10, state % 5 + 1, 0)
    for k in range(full * 8, n):
        b = bits[:, k].astype(np.int32)
        run = np.where(b == last, run + 1, 1)
        last = b
        stuffed = run == 5
        count += stuffed
        last = np.where(stuffed, 1 - b, last)
        run = np.where(stuffed, 1, run)
    return count
