# SPDX-License-Identifier: Apache-2.0
"""A node's DDS agent played by the Python cyclonedds package, for the interoperability test.

    python pypeer.py --domain D --node K --frames N

Creates the agent's four writers (same QoS, in DDS partition "nodeK") and readers, waits until
an agent's readers match them, publishes CrossChannelInputs for frames 0..N-1 (inputs_for of
dds_helpers), then prints every CrossChannelInputs sample it reads from other nodes as a JSON
line, until it has N of them or 20 s passed.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from dds_helpers import dds_inputs  # noqa: E402

from ima import dds  # noqa: E402


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--domain", type=int, required=True)
    p.add_argument("--node", type=int, required=True)
    p.add_argument("--frames", type=int, default=3)
    args = p.parse_args()
    dds.use_loopback_config()
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter, Publisher
    from cyclonedds.sub import DataReader, Subscriber
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    from ima.dds.types import TOPICS

    dp = DomainParticipant(args.domain)
    dds.bind_dds_sockets("lo")
    writers, readers = {}, {}
    # an agent tells a writer's node by its partition: node K writes in "nodeK"
    pub = Publisher(dp, qos=Qos(Policy.Partition([f"node{args.node}"])))
    sub = Subscriber(dp, qos=Qos(Policy.Partition(["node*"])))
    for name, cls in TOPICS.items():
        depth = 32 if name == "rpas_CrossChannelInputs" else 4
        pol = [Policy.Reliability.Reliable(duration(milliseconds=100)),
               Policy.History.KeepLast(depth), Policy.Durability.TransientLocal,
               Policy.DurabilityService(0, Policy.History.KeepLast(depth), -1, -1, -1),
               Policy.Liveliness.Automatic(duration(seconds=1))]
        if name == "rpas_NodeHealth":
            pol.append(Policy.Deadline(duration(milliseconds=150)))
        tp = Topic(dp, name, cls)
        writers[name] = DataWriter(pub, tp, qos=Qos(*pol, Policy.WriterDataLifecycle(False)))
        readers[name] = DataReader(sub, tp, qos=Qos(pol[0], pol[1], pol[2], pol[4]))
    end = time.monotonic() + 20
    wr = writers["rpas_CrossChannelInputs"]
    while not wr.get_matched_subscriptions() and time.monotonic() < end:
        time.sleep(0.01)
    for f in range(args.frames):
        wr.write(dds_inputs(args.node, f, 0b11))
    rd = readers["rpas_CrossChannelInputs"]
    got = 0
    while got < args.frames and time.monotonic() < end:
        for s in rd.take(N=32):
            if getattr(s, "sample_info", None) is not None and not s.sample_info.valid_data:
                continue
            if s.node != args.node:
                print(json.dumps(dataclasses.asdict(s)), flush=True)
                got += 1
        time.sleep(0.01)
    time.sleep(0.5)  # let the agent take what we wrote before we go
    return 0 if got >= args.frames else 1


if __name__ == "__main__":
    sys.exit(main())
