# SPDX-License-Identifier: Apache-2.0
"""Listens to the DDS topics of a live run and prints what the nodes publish.

    python -m ima.dds.listen --domain D [--topic NAME ...] [--count N] [--timeout S] [--json]

The run's domain id is in its run directory (and in each agent's trace, kind dds_ready). The
listener uses the loopback configuration like every DDS process of the product, binds its own
sockets to lo, and only reads: the agents do not wait for it. Its readers ask for the
writers' retained samples (transient local), so it starts with each node's latest ones.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import signal
import sys
import time

from ima import dds
from ima.errors import ImaError

# dds_sample_info_t.instance_state (DDS_IST_*)
INSTANCE_STATES = {16: "alive", 32: "disposed", 64: "no_writers"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ima.dds.types import TOPICS

    parser.add_argument("--domain", type=int, required=True, metavar="D",
                        help=f"the run's DDS domain id ({dds.DOMAIN_MIN}..{dds.DOMAIN_MAX})")
    parser.add_argument("--topic", action="append", choices=sorted(TOPICS), metavar="NAME",
                        help="a topic to print (repeatable; default: all of "
                        + ", ".join(TOPICS) + ")")
    parser.add_argument("--count", type=int, metavar="N", help="stop after N samples")
    parser.add_argument("--timeout", type=float, metavar="S",
                        help="stop after S seconds (exit status 1 if --count was not reached)")
    parser.add_argument("--json", action="store_true", help="one JSON object per sample")


def _to_json(topic: str, sample, t_wall_ns: int) -> dict:
    out = {"topic": topic, "t_recv_wall_ns": t_wall_ns}
    info = getattr(sample, "sample_info", None)
    if info is not None and not info.valid_data:
        # an instance changed state (a node's io link dropped, an agent went): its key only
        out["valid"] = False
        out["instance_state"] = INSTANCE_STATES.get(int(info.instance_state), "?")
        out["node"] = getattr(sample.key_sample, "node", None)
        return out
    out["valid"] = True
    # A state change that arrives while a sample is still unread marks that sample instead
    # of adding one: its instance_state says "disposed" or "no_writers".
    if info is not None:
        out["instance_state"] = INSTANCE_STATES.get(int(info.instance_state), "?")
    out["sample"] = dataclasses.asdict(sample)
    return out


def _to_text(topic: str, sample) -> str:
    info = getattr(sample, "sample_info", None)
    if info is not None and not info.valid_data:
        node = getattr(sample.key_sample, "node", "?")
        return f"{topic} node{node}: {INSTANCE_STATES.get(int(info.instance_state), '?')}"
    d = dataclasses.asdict(sample)
    head = f"{topic} node{d.pop('node')} frame {d.pop('frame')} t {d.pop('t_ns') / 1e9:.3f} s"
    rest = " ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}" for k, v in d.items())
    state = INSTANCE_STATES.get(int(info.instance_state), "?") if info is not None else "alive"
    return f"{head}: {rest}" + ("" if state == "alive" else f" [{state}]")


def listen(domain: int, topics: list[str] | None = None, count: int | None = None,
           timeout: float | None = None, out=sys.stdout, as_json: bool = False) -> int:
    """Prints samples until count or timeout; returns how many were printed."""
    if not dds.DOMAIN_MIN - 1 <= domain <= 232:
        raise ImaError(f"DDS domain {domain} out of range 0..232", exit_code=2)
    dds.use_loopback_config()  # before Cyclone creates the domain
    from cyclonedds.core import (
        InstanceState,
        Policy,
        Qos,
        ReadCondition,
        SampleState,
        ViewState,
        WaitSet,
    )
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.sub import DataReader, Subscriber
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    from ima.dds.types import TOPICS

    names = topics or list(TOPICS)
    dp = DomainParticipant(domain)
    dds.bind_dds_sockets("lo")
    qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)),
              Policy.Durability.TransientLocal, Policy.History.KeepLast(32))
    # each node publishes in its own DDS partition, "nodeK" (docs/security.md)
    sub = Subscriber(dp, qos=Qos(Policy.Partition(["node*"])))
    ws = WaitSet(dp)
    readers = []
    for name in names:
        rd = DataReader(sub, Topic(dp, name, TOPICS[name]), qos=qos)
        cond = ReadCondition(rd, SampleState.Any | ViewState.Any | InstanceState.Any)
        ws.attach(cond)
        readers.append((name, rd))
    printed = 0
    end = None if timeout is None else time.monotonic() + timeout
    while count is None or printed < count:
        left = None if end is None else end - time.monotonic()
        if left is not None and left <= 0:
            break
        ws.wait(duration(seconds=min(left, 1.0) if left is not None else 1.0))
        for name, rd in readers:
            for s in rd.take(N=64):
                t = time.time_ns()
                line = json.dumps(_to_json(name, s, t)) if as_json else _to_text(name, s)
                out.write(line + "\n")
                printed += 1
                if count is not None and printed >= count:
                    break
            if count is not None and printed >= count:
                break
        out.flush()
    return printed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ima.dds.listen", description=__doc__.split(
        "\n\n")[0])
    add_arguments(parser)
    args = parser.parse_args(argv)
    try:
        n = listen(args.domain, args.topic, args.count, args.timeout, as_json=args.json)
    except ImaError as e:
        print(f"ima.dds.listen: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        # Not swallowed: the process still ends by the signal, only without a traceback.
        sys.stdout.flush()
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
        raise
    except BrokenPipeError:
        # the reader of our output went away (| head): nothing more to say
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    return 1 if args.count is not None and n < args.count else 0


if __name__ == "__main__":
    sys.exit(main())
