# SPDX-License-Identifier: Apache-2.0
"""Following a run's traces (recording/follow.py) and the launcher's word to the recorder
(recording/__main__.py): the recorder reads what is left as soon as it is told the run has
ended, not after the rest of a poll's sleep."""

from __future__ import annotations

import os
import random
import time

from ima.recording import follow
from ima.recording.__main__ import _Stdin


def test_feed_until_pauses_as_told_and_reads_the_rest_once_ended(tmp_path):
    trace = tmp_path / "t.jsonl"
    trace.write_bytes(b'{"a":1}\n{"a":2}\n{"a"')  # a line still being written
    got: list[tuple[int, bytes]] = []
    pauses: list[float] = []
    state = {"ended": False}

    def pause(timeout: float) -> None:
        pauses.append(timeout)
        with open(trace, "ab") as f:  # the writer ends its line, then the run ends
            f.write(b':3}\n{"a":4')
        state["ended"] = True

    follow.feed_until([(trace, lambda b: got.extend(b.lines()))], lambda: state["ended"],
                      0.05, pause)
    assert pauses == [0.05]  # one read, one pause, then the rest: no second pause
    assert got == [(0, b'{"a":1}'), (1, b'{"a":2}'), (2, b'{"a":3}'), (3, b'{"a":4')]


def test_the_recorder_wait_returns_when_the_launcher_says_ended(monkeypatch):
    r, w = os.pipe()
    try:
        monkeypatch.setattr("sys.stdin", os.fdopen(r, "rb", buffering=0, closefd=False))
        stdin = _Stdin()
        t0 = time.monotonic()
        stdin.wait_ended(0.05)  # nothing said: the whole timeout
        assert time.monotonic() - t0 >= 0.04 and not stdin.ended
        os.write(w, b"ended\n")
        t0 = time.monotonic()
        stdin.wait_ended(30.0)  # told: at once, not after 30 s
        assert time.monotonic() - t0 < 5.0
        assert stdin.ended and stdin.run_ended() and not stdin.closed
        stdin.wait_ended(30.0)  # once ended, it no longer waits
        os.close(w)
        w = -1
        stdin.wait_closed()  # end of file: the summary is final
        assert stdin.closed
    finally:
        if w >= 0:
            os.close(w)
        os.close(r)


def test_lines_are_counted_by_the_c_as_bytes_count_counts_them(tmp_path):
    """The blocks' line numbers come from the C's count (recording/fast.py, line_counter)."""
    from ima.recording import fast

    assert fast.library() is not None, f"{fast.library_path()} is not built"
    count = fast.line_counter()
    rng = random.Random(7)
    cases = [b"", b"x", b"\n", b"\n\n", b"a\nb", b"a\nb\n", b"\0\n\0\xff\n"]
    cases += [bytes(rng.choice(b"ab\n\0") for _ in range(rng.randrange(1, 300)))
              for _ in range(200)]
    for data in cases:
        assert count(data) == data.count(b"\n"), data
    # and a trace followed block by block: each block numbered from the lines before it
    trace = tmp_path / "t.jsonl"
    trace.write_bytes(b"".join(b'{"i":%d}\n' % i for i in range(1000)))
    f = follow.Follow(trace)
    firsts = [(b.first, b.data.count(b"\n")) for b in f.blocks(777)]
    f.close()
    assert [first for first, _ in firsts] == \
        [sum(n for _, n in firsts[:k]) + firsts[0][0] for k in range(len(firsts))]
    assert sum(n for _, n in firsts) == 1000
