# SPDX-License-Identifier: Apache-2.0
"""Writers of CrossChannelInputs in chosen DDS partitions, keyed as chosen nodes: what a
participant without credentials can try on a run whose DDS Security is off.

    python pyforger.py --domain D [--writer PARTITIONS:NODE[:COUNT]]... [--gone N]

Each --writer is COUNT writers (default 1) publishing in the comma-separated PARTITIONS (empty:
the default partition), each writing one sample keyed as NODE once an agent's reader matches
it. --gone N first makes N writers in partition "node2" that write one sample keyed as node 2
and are deleted. Prints "done" once everything is written, then waits for stdin to close.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from dds_helpers import dds_inputs  # noqa: E402

from ima import dds  # noqa: E402


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--domain", type=int, required=True)
    p.add_argument("--writer", action="append", default=[])
    p.add_argument("--gone", type=int, default=0)
    args = p.parse_args()
    dds.use_loopback_config()
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter, Publisher
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    from ima.dds.types import CrossChannelInputs

    dp = DomainParticipant(args.domain)
    dds.bind_dds_sockets("lo")
    topic = Topic(dp, "rpas_CrossChannelInputs", CrossChannelInputs)
    qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)),
              Policy.History.KeepLast(32), Policy.Durability.TransientLocal,
              Policy.DurabilityService(0, Policy.History.KeepLast(32), -1, -1, -1),
              Policy.Liveliness.Automatic(duration(seconds=1)),
              Policy.WriterDataLifecycle(False))

    def write_all(specs: list[tuple[list[str], int]]) -> list:
        made = []
        for parts, node in specs:
            pub = Publisher(dp, qos=Qos(Policy.Partition(parts))) if parts else Publisher(dp)
            made.append((DataWriter(pub, topic, qos=qos), node))
        end = time.monotonic() + 20
        for wr, node in made:
            while not wr.get_matched_subscriptions() and time.monotonic() < end:
                time.sleep(0.01)
            wr.write(dds_inputs(node, 0, 0b11))
        return made

    gone = write_all([(["node2"], 2)] * args.gone)
    time.sleep(0.5)
    for wr, _ in gone:
        wr.__del__()  # deletes the DDS writer now: its readers see it unmatched
    specs = []
    for spec in args.writer:
        parts, node, count = (spec.split(":") + ["1"])[:3]
        specs += [([q for q in parts.split(",") if q], int(node))] * int(count)
    kept = write_all(specs)
    print("done", flush=True)
    sys.stdin.read()
    del kept
    return 0


if __name__ == "__main__":
    sys.exit(main())
