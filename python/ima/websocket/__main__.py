# SPDX-License-Identifier: Apache-2.0
"""python -m ima.websocket RUN_DIR --nodes A,B [--port P]: serves a run's channels over the
Foxglove WebSocket protocol while it flies (the launcher's `--live`).

It listens on 127.0.0.1, prints {"url", "port"} as one JSON line once it does, then follows
the run's traces (the bus's, each node's, the world's) and serves each line as it is
written, on the topics and with the schemas of run.mcap. When its standard input closes (the
run has ended) it serves what is left and stops."""

from __future__ import annotations

import argparse
import json
import select
import sys
from pathlib import Path

from ima.errors import ImaError
from ima.recording.follow import feed_until
from ima.recording.topics import Topics
from ima.websocket.server import DEFAULT_PORT, LiveServer

POLL_S = 0.05


def serve(run_dir: Path, nodes: list[str], port: int, stop) -> dict[str, int]:
    """Serves until stop() is true, then what is left; returns the messages per topic."""
    server = LiveServer(port, f"ima {run_dir.name}")
    topics = Topics(server)
    for topic, schema_name, schema in topics.topics(nodes):
        server.channel(topic, schema_name, schema)  # advertised before the run starts
    print(json.dumps({"url": server.url, "port": server.port}), flush=True)
    try:
        feed_until(topics.traces(run_dir, nodes), stop, POLL_S)
        return server.counts
    finally:
        server.stop()


def _stdin_closed() -> bool:
    ready, _, _ = select.select([sys.stdin], [], [], 0)
    return bool(ready) and not sys.stdin.buffer.read1(4096)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m ima.websocket")
    p.add_argument("run_dir", type=Path)
    p.add_argument("--port", type=int, default=DEFAULT_PORT)
    p.add_argument("--nodes", required=True, help="the run's nodes, comma-separated")
    args = p.parse_args(argv)
    try:
        counts = serve(args.run_dir, args.nodes.split(","), args.port, _stdin_closed)
    except ImaError as e:
        print(f"ima: {e}", file=sys.stderr)
        return 1
    print(json.dumps({"topics": counts}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
