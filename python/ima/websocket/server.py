# SPDX-License-Identifier: Apache-2.0
"""The Foxglove WebSocket server of `--live` (foxglove-sdk), on the loopback interface only:
one channel per topic, with the recording's schemas (JSON messages, JSON Schema), opened on
first use. A message's log time is its emulated time, as in run.mcap."""

from __future__ import annotations

from ima.errors import ImaError

HOST = "127.0.0.1"
DEFAULT_PORT = 8765


class LiveServer:
    """The sink the recording's converter writes to (put(), as its MCAP writer has)."""

    def __init__(self, port: int, name: str) -> None:
        import foxglove

        self._fg = foxglove
        self._ctx = foxglove.Context()
        try:
            self.server = foxglove.start_server(name=name, host=HOST, port=port,
                                                context=self._ctx)
        except (RuntimeError, OSError) as e:
            raise ImaError(f"--live: cannot serve on {HOST}:{port}: {e} (choose another "
                           "port with --live-port)") from e
        self.port = self.server.port
        self.channels: dict[str, object] = {}
        self.counts: dict[str, int] = {}

    @property
    def url(self) -> str:
        return f"ws://{HOST}:{self.port}"

    def channel(self, topic: str, schema_name: str, schema: bytes):
        """The topic's channel, advertised to the clients when it is opened."""
        ch = self.channels.get(topic)
        if ch is None:
            fg = self._fg
            ch = self.channels[topic] = fg.Channel(
                topic, message_encoding="json", context=self._ctx,
                schema=fg.Schema(name=schema_name, encoding="jsonschema", data=schema))
            self.counts[topic] = 0
        return ch

    def put(self, topic: str, schema_name: str, schema: bytes, t_ns: int, data: bytes,
            seq: int) -> None:
        ch = self.channels.get(topic) or self.channel(topic, schema_name, schema)
        ch.log(data, log_time=t_ns if t_ns > 0 else 0)
        self.counts[topic] += 1

    def stop(self) -> None:
        self.server.stop()
