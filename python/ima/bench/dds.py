# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the cross-channel link: the product's DDS latency against Cyclone's own ddsperf.

All figures come from the same run, the same configuration file (loopback only), the same
domain id, one after the other so that they do not compete for the CPU. ima-xch-bench plays
the io partitions of two nodes (one thread each) whose real agents (ima-dds-node, real-time
mode) exchange their inputs over DDS, 1000 rounds; in each, node B's io sends its INPUTS at
t0 and node A's io receives the AGREED holding them at t1.

- dds_latency_us (node to node): ONE-WAY latency of DDS between the two nodes' agents, with
  the product's types, QoS and threads: from agent B's dds_write of its inputs to agent A's
  take of them (in Cyclone's receive thread, the listener). Cyclone stamps each sample with
  the writer's clock; agent A subtracts it from its own clock on taking it. Both are this
  machine's clock. Each agent keeps these figures in its statistics (dds_latency_us).
- xch_latency_us (io to io): t1 - t0, both read on CLOCK_MONOTONIC. It adds the two hops
  inside the nodes: io B -> Unix socket -> agent B's main thread, and agent A -> Unix socket
  -> io A, each a process wake-up.
- ddsperf_latency_us: Cyclone's ddsperf ping/pong pair at a similar rate (500 Hz) on the same
  domain; ddsperf reports half the round trip, so it too is a one-way figure, of bare DDS.

ratio = dds / ddsperf: what the product's use of DDS costs over DDS's own tool.
xch_ratio = xch / ddsperf: that, plus the partition-to-agent hops within the nodes.

Each is measured twice: without security, and with DDS Security as runs have it by default
(the *_secure_* figures: the agents with their run identities, ddsperf with its own identity
of the same run, the same governance); secure_ratio = dds_secure / ddsperf_secure, and
security_cost_ratio = dds_secure / dds, what security costs the product.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from ima import dds, paths
from ima.dds import security
from ima.dds.agent import start_agents
from ima.dds.security import Material
from ima.errors import ImaError

DEFAULT_SAMPLES = 1000
DEFAULT_REPEATS = 3  # each side measured three times, alternately
GAP_US = 1000  # pause between the two nodes' INPUTS, and after each round
DDSPERF_SECONDS = 4  # the first second is warm-up, left out
DDSPERF_RATE = "500Hz"  # about our rate: one exchange per 2 ms
DDSPERF_IDENTITY = "ddsperf"  # its grant: every topic and partition of the benchmark's domain

# ddsperf's per-second line: "... size 12 mean 25.7us min 8.8us 50% 15.3us 90% 36.3us ... cnt 494"
DDSPERF_LINE = re.compile(r"size \d+ mean ([\d.]+)us min ([\d.]+)us 50% ([\d.]+)us "
                          r"90% ([\d.]+)us 99% ([\d.]+)us max ([\d.]+)us cnt (\d+)")


def _xch_bench() -> Path:
    path = paths.build_dir() / "nodes" / "dds" / "ima-xch-bench"
    if not path.is_file():
        raise ImaError(f"ima-xch-bench not built: run `cmake --build {paths.build_dir()}`")
    return path


def _product_latency(domain: int, samples: int, run_dir: Path,
                     material: Material | None = None) -> tuple[dict, dict]:
    """(io-to-io figures of ima-xch-bench, node A's agent's DDS latency statistics)."""
    agents = start_agents(2, run_dir, domain, realtime=True,
                          extra=["--xch-timeout-us", "100000"],
                          security=material if material is not None else "off")
    try:
        p = subprocess.run([str(_xch_bench()), "--socket-a", str(agents[0].socket),
                            "--socket-b", str(agents[1].socket), "--count", str(samples),
                            "--warmup", "50", "--gap-us", str(GAP_US)],
                           capture_output=True, text=True, timeout=60 + samples * 0.05)
    finally:
        for a in agents:
            a.stop()
    if p.returncode != 0:
        raise ImaError(f"ima-xch-bench failed: {p.stderr.strip()}")
    stats = agents[0].read_stats()
    node_to_node = (stats or {}).get("dds_latency_us") or {}
    if not node_to_node.get("count"):
        raise ImaError(f"node{agents[0].node}'s agent measured no DDS latency "
                       f"(statistics: {agents[0].stats})")
    io = json.loads(p.stdout)
    io_to_io = {"count": io["samples"], "min": io["min_us"], "median": io["median_us"],
                "p95": io["p95_us"], "incomplete": io["incomplete"]}
    return io_to_io, node_to_node


def parse_ddsperf(text: str) -> dict:
    """Medians over ddsperf's one-second intervals (the first one, warm-up, left out)."""
    rows = [tuple(float(x) for x in m.groups()) for m in DDSPERF_LINE.finditer(text)]
    if len(rows) > 1:
        rows = rows[1:]
    if not rows:
        raise ImaError("ddsperf reported no latency (did ping and pong meet?)")
    return {"median": round(statistics.median(r[2] for r in rows), 1),
            "p90": round(statistics.median(r[3] for r in rows), 1),
            "count": int(sum(r[6] for r in rows))}


def _ddsperf_latency(domain: int, seconds: int = DDSPERF_SECONDS,
                    material: Material | None = None) -> dict:
    exe = shutil.which("ddsperf")
    if not exe:
        raise ImaError("ddsperf not found (Debian package cyclonedds-tools)")
    env = dds.dds_env()
    if material is not None:  # the same plugins and governance as the agents, its own identity
        env["CYCLONEDDS_URI"] += "," + security.cyclone_xml(material, DDSPERF_IDENTITY)
    pong = subprocess.Popen([exe, "-D", str(seconds + 2), "-i", str(domain), "pong"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    try:
        ping = subprocess.run([exe, "-D", str(seconds), "-i", str(domain), "ping",
                               DDSPERF_RATE], capture_output=True, text=True, env=env,
                              timeout=seconds + 30)
    finally:
        pong.terminate()
        try:
            pong.wait(10)
        except subprocess.TimeoutExpired:
            pong.kill()
            pong.wait()
    return parse_ddsperf(ping.stdout)


def measure(samples: int = DEFAULT_SAMPLES, repeats: int = DEFAULT_REPEATS,
            progress=None, ddsperf_seconds: int = DDSPERF_SECONDS,
            secure_mode: str = security.DEFAULT_MODE) -> dict:
    """Runs both measurements `repeats` times, alternately, without security and then with
    DDS Security in `secure_mode` (the agents and ddsperf alike: the same governance, each
    its own identity); `progress(text)` is told what runs next. Each figure is the median of
    its per-repeat figures (min: the least; samples: the sum), so that a slow moment of the
    machine weighs on both sides alike."""
    say = progress or (lambda text: None)
    if samples < 1 or repeats < 1 or ddsperf_seconds < 2:
        raise ImaError("the DDS benchmark needs at least one sample, one repeat and two "
                       "seconds of ddsperf")
    domain = dds.domain_for_run()
    runs = []
    try:
        with tempfile.TemporaryDirectory(prefix="ima-bench-dds-") as tmp:
            material = security.prepare(Path(tmp), 2, domain, secure_mode, extra={
                DDSPERF_IDENTITY: (["*"], ["*"], ("*",))})
            for i in range(repeats):
                tag = f"{i + 1}/{repeats}"
                run = {}
                for sec, mat in (("", None), ("secure_", material)):
                    what = f"with DDS Security ({secure_mode})" if mat else "without security"
                    say(f"[{tag}] cross-channel exchange through two agents {what}: "
                        f"{samples} rounds")
                    run_dir = Path(tmp) / f"repeat{i + 1}{sec and '-secure'}"
                    run_dir.mkdir()
                    xch, ours = _product_latency(domain, samples, run_dir, mat)
                    say(f"[{tag}] ddsperf ping/pong at {DDSPERF_RATE} {what}: "
                        f"{ddsperf_seconds} s")
                    ref = _ddsperf_latency(domain, ddsperf_seconds, mat)
                    run.update({f"{sec}dds": ours, f"{sec}xch": xch, f"{sec}ddsperf": ref})
                runs.append(run)
    finally:
        dds.release_domain(domain)

    def med(side, key):
        return round(statistics.median(r[side][key] for r in runs), 1)

    def pooled(side):
        return {f"{side}_latency_us_median": med(side, "median"),
                f"{side}_latency_us_p95": med(side, "p95"),
                f"{side}_latency_us_min": min(r[side]["min"] for r in runs),
                f"{side}_latency_samples": sum(r[side]["count"] for r in runs)}

    def ratio(side, ref_side="ddsperf"):
        ref = med(ref_side, "median")
        return round(med(side, "median") / ref, 2) if ref else None

    return {
        **pooled("dds"),
        "dds_latency_measure": "one-way node to node: agent B's dds_write of its inputs -> "
                               "agent A's take (source timestamp against A's clock)",
        **pooled("xch"),
        "xch_latency_incomplete": sum(r["xch"]["incomplete"] for r in runs),
        "xch_latency_measure": "one-way io to io: io B's INPUTS -> io A's AGREED through both "
                               "agents, CLOCK_MONOTONIC",
        "ddsperf_latency_us_median": med("ddsperf", "median"),
        "ddsperf_latency_us_p90": med("ddsperf", "p90"),
        "ddsperf_samples": sum(r["ddsperf"]["count"] for r in runs),
        "ddsperf_measure": f"round trip / 2, ddsperf ping {DDSPERF_RATE} / pong",
        "ratio": ratio("dds"),
        "xch_ratio": ratio("xch"),
        "security": secure_mode,
        "dds_latency_secure_us_median": med("secure_dds", "median"),
        "dds_latency_secure_us_p95": med("secure_dds", "p95"),
        "xch_latency_secure_us_median": med("secure_xch", "median"),
        "ddsperf_secure_latency_us_median": med("secure_ddsperf", "median"),
        "ddsperf_secure_latency_us_p90": med("secure_ddsperf", "p90"),
        "secure_ratio": ratio("secure_dds", "secure_ddsperf"),
        "secure_xch_ratio": ratio("secure_xch", "secure_ddsperf"),
        "security_cost_ratio": ratio("secure_dds", "dds"),
        "repeats": [{f"{side}_us": r[side]["median"]
                     for side in ("dds", "xch", "ddsperf", "secure_dds", "secure_xch",
                                  "secure_ddsperf")}
                    for r in runs],
        "domain": domain,
        "config": str(dds.config_path()),
        "cpus": os.cpu_count(),
    }


def run(json_out: bool = False, samples: int = DEFAULT_SAMPLES,
        repeats: int = DEFAULT_REPEATS) -> int:
    """Runs the benchmark, prints JSON if `json_out` (else a table); exit code."""
    from rich.console import Console

    err = Console(stderr=True)
    if json_out:
        with err.status("benchmarking the DDS link") as status:
            result = measure(samples, repeats, progress=lambda text: status.update(text))
        json.dump(result, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    out = Console()
    with out.status("benchmarking the DDS link") as status:
        result = measure(samples, repeats, progress=lambda text: status.update(text))
    out.print("[bold]DDS cross-channel benchmark[/bold]")
    for key, value in result.items():
        out.print(f"  {key:28} {value}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ima.bench.dds", description=__doc__.split(
        "\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.add_argument("--samples", type=int, default=DEFAULT_SAMPLES, metavar="N",
                        help=f"exchange rounds measured (default {DEFAULT_SAMPLES})")
    parser.add_argument("--repeats", type=int, default=DEFAULT_REPEATS, metavar="N",
                        help=f"times each side is measured, alternately (default "
                             f"{DEFAULT_REPEATS})")
    args = parser.parse_args(argv)
    try:
        return run(json_out=args.json, samples=args.samples, repeats=args.repeats)
    except ImaError as e:
        print(f"ima.bench.dds: {e}", file=sys.stderr)
        return e.exit_code


if __name__ == "__main__":
    sys.exit(main())
