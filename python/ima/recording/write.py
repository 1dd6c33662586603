# SPDX-License-Identifier: Apache-2.0
"""RUN_DIR/run.mcap from the traces a run leaves (docs/recording.md).

The recording is made from the producers' own traces: while the run flies, following them as
they grow (the launcher's way), or once it has ended, or from whatever a killed run left
(`ima trace recover`). After Ctrl-C every trace is complete up to the stop; a line cut by a
kill is skipped and counted. Each message's log time is the record's emulated time (t_ns);
its sequence number is the record's number (its line, from 0) in its producer's trace, so a
reader can check that nothing was dropped. The file is written beside as run.mcap.part and
renamed when complete.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import orjson

from ima.errors import ImaError
from ima.recording import fast, schemas
from ima.recording.follow import feed_all, feed_until

NAME = "run.mcap"
CHUNK_BYTES = 1 << 20
ZSTD_LEVEL = 1  # the traces' JSON: as small as level 3 here, and faster
POLL_S = 0.05  # how often a followed run's traces are read
READ_BLOCK = 1 << 22  # a complete trace is read this many bytes at a time


class _Out:
    """The MCAP writer with its schemas and channels, registered on first use."""

    def __init__(self, f) -> None:
        from ima.recording.mcapfile import McapWriter

        self.w = McapWriter(f, chunk_bytes=CHUNK_BYTES, level=ZSTD_LEVEL)
        self.schemas: dict[str, int] = {}
        self.channels: dict[str, int] = {}

    def channel(self, topic: str, schema_name: str, schema: bytes) -> int:
        ch = self.channels.get(topic)
        if ch is None:
            sid = self.schemas.get(schema_name)
            if sid is None:
                sid = self.schemas[schema_name] = len(self.schemas) + 1
                self.w.schema(sid, schema_name, "jsonschema", schema)
            ch = self.channels[topic] = len(self.channels) + 1
            self.w.channel(ch, sid, topic, "json")
        return ch

    @property
    def counts(self) -> dict[str, int]:
        return {t: self.w.counts[c] for t, c in self.channels.items()}

    def put(self, topic: str, schema_name: str, schema: bytes, t_ns: int, data: bytes,
            seq: int) -> None:
        ch = self.channels.get(topic) or self.channel(topic, schema_name, schema)
        self.w.message(ch, seq, t_ns if t_ns > 0 else 0, data)


def _fdr(out: _Out, run_dir: Path, node: str) -> None:
    """A node's flight data recorder file: a message for each good record, numbered among
    them in file order (ima.fdr.records' decoding with its "kind"; the frame records, nearly
    all, by the C when it is built)."""
    try:
        data = (run_dir / f"{node}.fdr").read_bytes()
    except OSError:  # none (a node without the recorder), or not readable
        return
    from ima.fdr import records

    size = records.RECORD_SIZE
    topic = f"/{node}/fdr"

    def put(k: int, seq: int) -> bool:  # record k as message `seq`; False if it is torn
        got = records.decode(data[k * size:(k + 1) * size], k * size)
        if got is None:
            return False
        kind, r = got
        out.put(topic, "ima.FdrRecord", schemas.FDR, r.get("t_ns") or 0,
                orjson.dumps({"kind": kind, **r}, default=str), seq)
        return True

    if fast.fdr(out, topic, data, put):
        return
    seq = 0
    for k in range(len(data) // size):
        seq += put(k, seq)


def _verdicts(out: _Out, run_dir: Path, launch: dict) -> None:
    for i, f in enumerate(launch.get("faults") or []):
        t = round(float(f.get("t_s") or 0) * 1e9)
        out.put("/faults", "ima.Fault", schemas.event("ima.Fault", "A fault the run injects"),
                t, orjson.dumps(f), i)
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return
    if summary.get("oracles"):
        t = round(float(summary.get("flown_s") or 0) * 1e9)
        judged = {k: summary.get(k) for k in ("outcome", "oracles", "violations", "faults",
                                              "golden") if k in summary}
        out.put("/oracles", "ima.Verdicts", schemas.VERDICT, t,
                orjson.dumps(judged, default=str), 0)


def _metadata(out: _Out, run_dir: Path, launch: dict) -> None:
    from ima import provenance

    meta = {k: json.dumps(launch.get(k)) for k in ("kind", "system", "nodes", "seed",
                                                   "duration_s", "pilot", "dds_domain",
                                                   "faults", "commands") if k in launch}
    try:
        prov = json.loads((run_dir / "summary.json").read_text()).get("provenance")
    except (OSError, ValueError):
        prov = None
    meta["provenance"] = json.dumps(prov or provenance.provenance())
    out.w.metadata("ima.run", meta)


def record(run_dir: Path, output: Path | None = None, before_verdicts=None,
           follow=None, nodes: list[str] | None = None, pause=time.sleep) -> dict:
    """Writes the recording of run_dir; returns its counts: messages per topic, lines skipped
    (cut by a kill). `before_verdicts()` is called once the traces are in, before the
    summary's verdicts are read (the launcher's recorder waits there for the summary).

    With `follow`, the run is still flying: the traces are followed as they grow, every
    POLL_S, until `follow()` says the run's processes have ended (the launcher's recorder:
    the recording is made on the CPU the lockstep leaves idle); `pause(POLL_S)` passes the time
    between two reads (a sleep; the launcher's recorder returns early when told the run has
    ended); `nodes` then names the run's nodes (launch.json may not exist yet)."""
    run_dir = Path(run_dir)
    if follow is None and not (run_dir / "can.jsonl").exists() and not (
            run_dir / "truth.jsonl").exists():
        raise ImaError(f"{run_dir}: not a run directory (no can.jsonl, no truth.jsonl)")
    output = Path(output) if output else run_dir / NAME
    part = output.with_name(output.name + ".part")
    try:
        with open(part, "w+b") as f:
            out = _Out(f)
            topics = fast.topics(out)
            try:
                if follow is not None:
                    feed_until(topics.traces(run_dir, list(nodes or [])), follow, POLL_S,
                               pause)
                launch = _launch(run_dir)
                nodes = list(nodes or launch.get("nodes") or sorted(
                    p.stem for p in run_dir.glob("node*.jsonl") if p.stem[4:].isdigit()))
                if follow is None:
                    feed_all(topics.traces(run_dir, nodes), READ_BLOCK)
                for node in nodes:
                    _fdr(out, run_dir, node)
                if before_verdicts is not None:
                    before_verdicts()
                _verdicts(out, run_dir, launch)
                _metadata(out, run_dir, launch)
                out.w.finish()
            finally:
                fast.close(topics)  # its C converters
        os.replace(part, output)
    except OSError as e:
        part.unlink(missing_ok=True)
        raise ImaError(f"{output}: cannot write the recording: {e.strerror}") from e
    return {"file": str(output), "bytes": output.stat().st_size, "topics": out.counts,
            "skipped_lines": topics.skipped}


def _launch(run_dir: Path) -> dict:
    try:
        return json.loads((run_dir / "launch.json").read_text())
    except (OSError, ValueError):
        return {}
