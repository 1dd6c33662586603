# SPDX-License-Identifier: Apache-2.0
"""The complete lines a growing trace file has gained since the last look, numbered from 0 as
the recording numbers them. A line still being written stays for the next look. (The
recorder and the live server follow a run's traces with it.)

They come as blocks: the bytes of whole lines, each ended by its newline, with the number of
the first (a cut last line, once the file is complete, without its newline). The recording's
C takes a block as it is (recording/fast.py); the others read its lines."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import NamedTuple


_count: Callable[[bytes], int] | None = None


def count_lines(data: bytes) -> int:
    """How many lines end in `data` (recording/fast.py's line_counter, looked up once)."""
    global _count
    if _count is None:
        from ima.recording.fast import line_counter  # it imports this module

        _count = line_counter()
    return _count(data)


class Block(NamedTuple):
    first: int  # the number of the first line
    data: bytes

    def lines(self) -> list[tuple[int, bytes]]:
        """(number, line without its newline) of each line."""
        parts = self.data.split(b"\n")
        if parts[-1] == b"":
            parts.pop()  # after the last newline
        return list(enumerate(parts, self.first))


class Follow:
    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._f = None
        self._tail = b""
        self._next = 0  # the number of the next complete line

    def new_block(self) -> Block | None:
        """The lines completed since the last call (None: none, or no file yet)."""
        return self._block(self._read(-1))

    def blocks(self, size: int):
        """Every line of a complete file, `size` bytes read at a time (a cut last line too)."""
        while data := self._read(size):
            block = self._block(data)
            if block:
                yield block
        yield from self.rest()

    def _read(self, size: int) -> bytes:
        if self._f is None:
            try:
                self._f = open(self.path, "rb")  # noqa: SIM115 - closed in close()
            except OSError:
                return b""
        return self._f.read(size)

    def _block(self, data: bytes) -> Block | None:
        if not data:
            return None
        data = self._tail + data
        end = data.rfind(b"\n") + 1
        self._tail = data[end:]
        if not end:
            return None
        block = Block(self._next, data[:end])
        self._next += count_lines(block.data)
        return block

    def rest(self) -> list[Block]:
        """Once the file is complete: what new_block() has not read, and the last line if its
        writer never ended it (a cut line: the reader skips and counts it)."""
        blocks = [b for b in (self.new_block(),) if b]
        if self._tail:
            blocks.append(Block(self._next, self._tail))
            self._next += 1
            self._tail = b""
        return blocks

    def close(self) -> None:
        if self._f is not None:
            self._f.close()
            self._f = None


def feed_until(traces: Iterable[tuple[Path, Callable[[Block], None]]], ended: Callable[[], bool],
               poll_s: float, pause: Callable[[float], None] = time.sleep) -> None:
    """Follows each (trace, feed) and hands feed its new lines every poll_s until ended() is
    true (the writers have stopped), then what is left, a cut last line included. Between
    two reads it calls pause(poll_s): a sleep, or a wait that returns as soon as the run ends
    (the launcher's recorder, whose last reads are on the run's critical path)."""
    follows = [(Follow(path), feed) for path, feed in traces]
    try:
        while not ended():
            for f, feed in follows:
                block = f.new_block()
                if block:
                    feed(block)
            pause(poll_s)
        for f, feed in follows:
            for block in f.rest():
                feed(block)
    finally:
        for f, _ in follows:
            f.close()


def feed_all(traces: Iterable[tuple[Path, Callable[[Block], None]]], size: int) -> None:
    """Hands each complete trace's lines to its feed, `size` bytes read at a time."""
    for path, feed in traces:
        f = Follow(path)
        try:
            for block in f.blocks(size):
                feed(block)
        finally:
            f.close()
