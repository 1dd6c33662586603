# SPDX-License-Identifier: Apache-2.0
"""The complete lines a growing trace file has gained since the last look, numbered from 0 as
the recording numbers them. A line still being written stays for the next look. (The
recorder and the live server follow a run's traces with it.)"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from pathlib import Path


class Follow:
    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._f = None
        self._tail = b""
        self._next = 0  # the number of the next complete line

    def new_lines(self) -> list[tuple[int, bytes]]:
        """(number, line without its newline) of every line completed since the last call;
        nothing while the file does not exist."""
        return self._split(self._read(-1))

    def blocks(self, size: int):
        """Every line of a complete file, `size` bytes read at a time (a cut last line too):
        lists of (number, line)."""
        while data := self._read(size):
            yield self._split(data)
        yield self.rest()

    def _read(self, size: int) -> bytes:
        if self._f is None:
            try:
                self._f = open(self.path, "rb")  # noqa: SIM115 - closed in close()
            except OSError:
                return b""
        return self._f.read(size)

    def _split(self, data: bytes) -> list[tuple[int, bytes]]:
        if not data:
            return []
        parts = (self._tail + data).split(b"\n")
        self._tail = parts.pop()
        first = self._next
        self._next += len(parts)
        return list(enumerate(parts, first))

    def rest(self) -> list[tuple[int, bytes]]:
        """The last line if its writer never ended it (a cut line: the reader skips and counts
        it), once the file is complete; read first what new_lines() has not."""
        lines = self.new_lines()
        if self._tail:
            lines.append((self._next, self._tail))
            self._next += 1
            self._tail = b""
        return lines

    def close(self) -> None:
        if self._f is not None:
            self._f.close()
            self._f = None


def feed_until(traces: Iterable[tuple[Path, Callable]], ended: Callable[[], bool],
               poll_s: float) -> None:
    """Follows each (trace, feed) and hands feed its new lines every poll_s until ended() is
    true (the writers have stopped), then what is left, a cut last line included."""
    follows = [(Follow(path), feed) for path, feed in traces]
    try:
        while not ended():
            for f, feed in follows:
                lines = f.new_lines()
                if lines:
                    feed(lines)
            time.sleep(poll_s)
        for f, feed in follows:
            lines = f.rest()
            if lines:
                feed(lines)
    finally:
        for f, _ in follows:
            f.close()
