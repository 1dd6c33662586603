# SPDX-License-Identifier: Apache-2.0
"""The recording's bulk in C: the bus's trace (can.jsonl) and each SKE's trace (nodeK.jsonl),
handed over a block at a time as read, and the flight data recorders' frame records, turned
into MCAP messages by nodes/src/trace_mcap.c and trace_mcap_fdr.c (ctypes on
libima_trace_mcap.so), written straight into the chunk being built. They are nine tenths of a
recording's messages, and the Python costs a few microseconds for each.

The C writes what Topics.can and Topics.ske write, byte for byte (tests/recording/
test_fast.py compares whole recordings). A line it does not handle (an event, a cut or garbled
line, the first frame of an id) it hands back: Topics handles that line, and the C is told
what Topics learned from it (a new channel, a frame's added fields). Without the library the
recording is the Python's alone: the same file, made more slowly.

The library is $IMA_TRACE_MCAP_LIB, else <build dir>/nodes/libima_trace_mcap.so."""

from __future__ import annotations

import ctypes
import os
from array import array
from collections.abc import Callable, Iterable
from functools import partial
from pathlib import Path

import orjson

from ima.recording.follow import Block
from ima.recording.topics import Topics

TM_CAN, TM_SKE, TM_FDR = 1, 2, 3
TM_DONE, TM_PYTHON, TM_FULL = 0, 1, 2
TM_CAN_FRAMES, TM_SKE_SCHEDULE, TM_SKE_HM, TM_SKE_OTHER, TM_FDR_RECORDS = 0, 0, 1, 2, 0

Lines = Iterable[tuple[int, bytes]]


class _Result(ctypes.Structure):
    _fields_ = [("consumed", ctypes.c_size_t), ("lines", ctypes.c_uint64),
                ("part", ctypes.c_uint32), ("out", ctypes.c_void_p),
                ("out_len", ctypes.c_size_t)]


def library_path() -> Path:
    env = os.environ.get("IMA_TRACE_MCAP_LIB")
    if env:
        return Path(env)
    from ima import paths
    return paths.build_dir() / "nodes" / "libima_trace_mcap.so"


_lib: ctypes.CDLL | None | bool = False  # False: not looked for yet


def library() -> ctypes.CDLL | None:
    """The library, or None if it is not built (the recording is then the Python's)."""
    global _lib
    if _lib is False:
        try:
            lib = ctypes.CDLL(str(library_path()))
            _declare(lib)
        except (OSError, AttributeError):  # not built, or an older build without a symbol
            _lib = None
            return None
        _lib = lib
    return _lib


def _declare(lib: ctypes.CDLL) -> None:
    c = ctypes
    for name, res, args in (
            ("tm_new", c.c_void_p, [c.c_int]),
            ("tm_free", None, [c.c_void_p]),
            ("tm_set_channel", None, [c.c_void_p, c.c_int, c.c_uint16]),
            ("tm_can_message", c.c_int, [c.c_void_p, c.c_uint32, c.c_uint32, c.c_uint16,
                                         c.c_int]),
            ("tm_can_signal", c.c_int, [c.c_void_p, c.c_uint32, c.c_uint32, c.c_uint32,
                                        c.c_int, c.c_int, c.c_double, c.c_double, c.c_char_p]),
            ("tm_can_key", c.c_int, [c.c_void_p, c.c_uint32, c.c_int, c.c_char_p, c.c_size_t]),
            ("tm_convert", c.c_int, [c.c_void_p, c.c_void_p, c.c_size_t, c.c_uint64,
                                     c.c_uint64, c.c_uint64, c.c_uint32, c.POINTER(_Result)]),
            ("tm_channels", c.c_size_t, [c.c_void_p, c.POINTER(c.POINTER(c.c_uint16))]),
            ("tm_entries", c.c_size_t, [c.c_void_p, c.c_uint16,
                                        c.POINTER(c.POINTER(c.c_uint64))]),
            ("tm_fdr", c.c_int, [c.c_void_p, c.c_void_p, c.c_size_t, c.c_size_t, c.c_uint64,
                                 c.c_uint64, c.c_uint64, c.POINTER(_Result)]),
            ("tm_format_double", c.c_size_t, [c.c_double, c.c_char_p]),
            ("tm_count_lines", c.c_uint64, [c.c_char_p, c.c_size_t])):
        f = getattr(lib, name)
        f.restype, f.argtypes = res, args


_memory = ctypes.pythonapi.PyMemoryView_FromMemory
_memory.restype, _memory.argtypes = ctypes.py_object, [ctypes.c_void_p, ctypes.c_ssize_t,
                                                       ctypes.c_int]
_PYBUF_READ = 0x100


def _view(address: int, n: int) -> memoryview:
    """A read-only view of n bytes of the C's memory (no copy, no ctypes type per length)."""
    return _memory(address, n, _PYBUF_READ)


def line_counter() -> Callable[[bytes], int]:
    """How many lines end in a block (its newline bytes): the C's count where the library is
    built (some ten times faster than bytes.count), else bytes.count."""
    lib = library()
    if lib is None:
        return lambda data: data.count(b"\n")
    count = lib.tm_count_lines
    return lambda data: count(data, len(data))


class _Converter:
    """Feeds one trace's lines to a C converter writing into `out`'s chunk; the lines it hands
    back go to `python` (Topics' feeder), after which `learn()` tells the C what is new."""

    def __init__(self, lib: ctypes.CDLL, kind: int, out, python: Callable[[Lines], None]) -> None:
        self.lib, self.out, self.python = lib, out, python
        self.conv = lib.tm_new(kind)
        if not self.conv:
            raise MemoryError("trace_mcap: no converter")
        self._res = _Result()

    def close(self) -> None:
        if self.conv:
            self.lib.tm_free(self.conv)
            self.conv = None

    def learn(self) -> None:  # what Topics has registered since
        pass

    def block(self, block: Block) -> None:
        """A block of the trace's lines as read (recording/follow.py), handed to the C as it
        is: only the lines the C hands back are split out."""
        data = block.data
        addr = ctypes.cast(ctypes.c_char_p(data), ctypes.c_void_p).value  # read only, no copy
        lib, conv, res, w = self.lib, self.conv, self._res, self.out.w
        pos, num, skip = 0, block.first, 0
        while pos < len(data):
            used = w.chunk_used()
            rc = self._taken(lib.tm_convert(conv, addr + pos, len(data) - pos, num, used,
                                            max(0, w.chunk_bytes - used), skip,
                                            ctypes.byref(res)))
            pos += res.consumed
            num += res.lines
            skip = res.part if rc == TM_FULL else 0
            if rc == TM_PYTHON and pos < len(data):  # a line the C leaves to the Python
                end = data.find(b"\n", pos)
                end = len(data) if end < 0 else end  # a cut last line
                self.python([(num, data[pos:end])])
                self.learn()
                pos, num = end + 1, num + 1

    def _taken(self, rc: int) -> int:
        """A call's answer, its records put into the chunk being built."""
        if rc < 0:
            raise MemoryError("trace_mcap: out of memory")
        res = self._res
        if res.out_len:
            entries = self._entries()
            # the C's buffer, valid until its next conversion, read in place and copied once:
            # into the chunk
            self.out.w.add_records(_view(res.out, res.out_len), entries)
        return rc

    def _entries(self) -> list[tuple[int, array]]:
        """The last call's index entries, channel by channel in the order of each one's first
        record (as the writer's own message() would have made them)."""
        cids = ctypes.POINTER(ctypes.c_uint16)()
        pairs = ctypes.POINTER(ctypes.c_uint64)()
        out = []
        for j in range(self.lib.tm_channels(self.conv, ctypes.byref(cids))):
            cid = cids[j]
            n = self.lib.tm_entries(self.conv, cid, ctypes.byref(pairs))
            if n:
                out.append((cid, array("Q", ctypes.string_at(pairs, 8 * n))))
        return out


class CanConverter(_Converter):
    """The bus's trace: its frames and their signals (Topics.can)."""

    def __init__(self, lib: ctypes.CDLL, out, topics: Topics) -> None:
        super().__init__(lib, TM_CAN, out, partial(Topics.can, topics))
        from ima.canbus import codec

        self.topics = topics
        self._keys: set = set()
        self._python_ids: set[int] = set()  # DBC ids the C could not take: theirs stay Python's
        self._signals: dict[int, str] = {}  # DBC id -> its signals' topic, until it has one
        for msg in codec.BY_ID.values():
            supported = self._supported(msg)
            if lib.tm_can_message(self.conv, msg.frame_id, msg.length, 0, supported) != 0:
                self._python_ids.add(msg.frame_id)  # too long, or too many for its table
                continue
            if supported:
                for s in msg.signals:
                    if lib.tm_can_signal(self.conv, msg.frame_id, s.start, s.length, s.signed,
                                         codec.integral(s.scale) and codec.integral(s.offset),
                                         s.scale, s.offset, orjson.dumps(s.name) + b":") != 0:
                        lib.tm_can_message(self.conv, msg.frame_id, msg.length, 0, 0)
                        supported = False
                        break
            if supported:
                self._signals[msg.frame_id] = f"/can/signals/{msg.name}"
        self.learn()

    @staticmethod
    def _supported(msg) -> bool:
        """Whether its signals message is a plain JSON object of its signals (the C refuses
        itself what it cannot decode: long frames, signals over 53 bits)."""
        names = msg.signal_names
        return bool(names) and len(set(names)) == len(names) and not {"t_ns", "from"} & set(names)

    def learn(self) -> None:
        from ima.canbus import codec

        lib, conv, channels = self.lib, self.conv, self.out.channels
        cid = channels.get("/can/frames")
        if cid:
            lib.tm_set_channel(conv, TM_CAN_FRAMES, cid)
        for key, extra in self.topics._extra_of.items():
            if key in self._keys:
                continue
            self._keys.add(key)
            frame_id, kind, ext = key
            if kind == "can_tx" and type(frame_id) is int and 0 <= frame_id < 2**32 \
                    and frame_id not in self._python_ids:
                lib.tm_can_key(conv, frame_id, ext, extra, len(extra))
        for frame_id, topic in list(self._signals.items()):
            cid = channels.get(topic)
            if cid:
                lib.tm_can_message(conv, frame_id, codec.BY_ID[frame_id].length, cid, 1)
                del self._signals[frame_id]


class SkeConverter(_Converter):
    """A node's SKE trace: its schedule, its health monitor's events, the rest (Topics.ske)."""

    def __init__(self, lib: ctypes.CDLL, out, topics: Topics, node: str) -> None:
        super().__init__(lib, TM_SKE, out, partial(Topics.ske, topics, node))
        self.topics = {TM_SKE_SCHEDULE: f"/{node}/schedule", TM_SKE_HM: f"/{node}/hm",
                       TM_SKE_OTHER: f"/{node}/events"}
        self.learn()

    def learn(self) -> None:
        for which, topic in list(self.topics.items()):
            cid = self.out.channels.get(topic)
            if cid:
                self.lib.tm_set_channel(self.conv, which, cid)
                del self.topics[which]


class FdrConverter(_Converter):
    """A flight data recorder file's records (fdr())."""

    def __init__(self, lib: ctypes.CDLL, out) -> None:
        super().__init__(lib, TM_FDR, out, None)

    def __call__(self, topic: str, data: bytes, python: Callable[[int, int], bool]) -> None:
        """The file's records as fdr() says."""
        from ima.fdr.records import RECORD_SIZE

        n = len(data) // RECORD_SIZE
        addr = ctypes.cast(ctypes.c_char_p(data), ctypes.c_void_p)  # read only, no copy
        lib, conv, res, out = self.lib, self.conv, self._res, self.out
        k = seq = 0
        while k < n:
            cid = out.channels.get(topic)
            if cid:
                lib.tm_set_channel(conv, TM_FDR_RECORDS, cid)
            used = out.w.chunk_used()
            rc = self._taken(lib.tm_fdr(conv, addr, n, k, seq, used,
                                        max(0, out.w.chunk_bytes - used), ctypes.byref(res)))
            k, seq = res.consumed, seq + res.lines
            if rc == TM_PYTHON:
                seq += python(k, seq)
                k += 1


def fdr(out, topic: str, data: bytes, python: Callable[[int, int], bool]) -> bool:
    """A flight data recorder file's records as messages of `topic` (write.py's _fdr): the
    frame records by the C, each record it hands back by `python(k, seq)` (record k, numbered
    seq among the good ones; it puts the message, or says the record is torn). False if the
    library is not built (nothing done)."""
    lib = library()
    if lib is None:
        return False
    conv = FdrConverter(lib, out)
    try:
        conv(topic, data, python)
    finally:
        conv.close()
    return True


class FastTopics(Topics):
    """Topics writing into an MCAP file (write.py's _Out) with the bus's and the SKEs' lines
    converted by the C: the blocks its traces() feeds take (fed lines, can() and ske() are
    Topics', in Python)."""

    def __init__(self, out, lib: ctypes.CDLL) -> None:
        super().__init__(out)
        self._lib = lib
        self._can: CanConverter | None = None
        self._ske: dict[str, SkeConverter] = {}

    def traces(self, run_dir, nodes):
        """Topics.traces(), the bus's and the SKEs' blocks handed to the C as they are."""
        out = super().traces(run_dir, nodes)
        fast = {f"{node}.jsonl": partial(self._ske_block, node) for node in nodes}
        fast["can.jsonl"] = self._can_block
        return [(path, fast.get(path.name, feed)) for path, feed in out]

    def _can_converter(self) -> CanConverter:
        if self._can is None:
            self._can = CanConverter(self._lib, self.out, self)
        return self._can

    def _ske_converter(self, node: str) -> SkeConverter:
        conv = self._ske.get(node)
        if conv is None:
            conv = self._ske[node] = SkeConverter(self._lib, self.out, self, node)
        return conv

    def _can_block(self, block: Block) -> None:
        self._can_converter().block(block)

    def _ske_block(self, node: str, block: Block) -> None:
        self._ske_converter(node).block(block)

    def close(self) -> None:
        for conv in [self._can, *self._ske.values()]:
            if conv is not None:
                conv.close()


def topics(out) -> Topics:
    """The recording's Topics for an MCAP file: FastTopics if the library is built (close()
    it when done)."""
    lib = library()
    return Topics(out) if lib is None else FastTopics(out, lib)


def close(topics: Topics) -> None:
    """Frees what topics() made in C."""
    if isinstance(topics, FastTopics):
        topics.close()


def format_double(x: float) -> bytes | None:
    """A float as the C writes it into a signals message (for the tests); None without the
    library or for a NaN or an infinity."""
    lib = library()
    if lib is None:
        return None
    buf = ctypes.create_string_buffer(40)
    n = lib.tm_format_double(x, buf)
    return buf.raw[:n] if n else None
