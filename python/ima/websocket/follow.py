# SPDX-License-Identifier: Apache-2.0
"""The complete lines a growing trace file has gained since the last look, numbered from 0 as
the recording numbers them. A line still being written stays for the next look."""

from __future__ import annotations

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
        if self._f is None:
            try:
                self._f = open(self.path, "rb")  # noqa: SIM115 - closed in close()
            except OSError:
                return []
        data = self._f.read()
        if not data:
            return []
        parts = (self._tail + data).split(b"\n")
        self._tail = parts.pop()
        first = self._next
        self._next += len(parts)
        return list(enumerate(parts, first))

    def close(self) -> None:
        if self._f is not None:
            self._f.close()
            self._f = None
