# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the cross-channel link: the product's DDS latency against Cyclone's own ddsperf.

Both figures come from the same run, the same configuration file (loopback only), the same
domain id, one after the other so that they do not compete for the CPU:

- dds_latency_us: ONE-WAY latency of the product's path, measured by ima-xch-bench playing
  the io partitions of two nodes whose real agents (ima-dds-node, real-time mode) talk over
  DDS: node B's io sends its INPUTS at t0, node A's io receives the AGREED holding them at t1.
  Both instants are read in the same process on CLOCK_MONOTONIC, so no two clocks are
  compared. The path: io B -> Unix socket -> agent B -> dds_write -> UDP on lo -> agent A's
  Cyclone receive thread -> agent A's main thread -> Unix socket -> io A.
- ddsperf_latency_us: Cyclone's ddsperf ping/pong pair at a similar rate (500 Hz) on the same
  domain; ddsperf reports half the round trip, so it too is a one-way figure, of bare DDS.

ratio = dds / ddsperf: the price of the agent process and its two Unix-socket hops.
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
from ima.dds.agent import start_agents
from ima.errors import ImaError

DEFAULT_SAMPLES = 1000
GAP_US = 1000  # pause between the two nodes' INPUTS, and after each round
DDSPERF_SECONDS = 5
DDSPERF_RATE = "500Hz"  # about our rate: one exchange per 2 ms

# ddsperf's per-second line: "... size 12 mean 25.7us min 8.8us 50% 15.3us 90% 36.3us ... cnt 494"
DDSPERF_LINE = re.compile(r"size \d+ mean ([\d.]+)us min ([\d.]+)us 50% ([\d.]+)us "
                          r"90% ([\d.]+)us 99% ([\d.]+)us max ([\d.]+)us cnt (\d+)")


def _xch_bench() -> Path:
    path = paths.build_dir() / "nodes" / "dds" / "ima-xch-bench"
    if not path.is_file():
        raise ImaError(f"ima-xch-bench not built: run `cmake --build {paths.build_dir()}`")
    return path


def _product_latency(domain: int, samples: int, run_dir: Path) -> dict:
    agents = start_agents(2, run_dir, domain, realtime=True,
                          extra=["--xch-timeout-us", "100000"])
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
    return json.loads(p.stdout)


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


def _ddsperf_latency(domain: int) -> dict:
    exe = shutil.which("ddsperf")
    if not exe:
        raise ImaError("ddsperf not found (Debian package cyclonedds-tools)")
    env = dds.dds_env()
    pong = subprocess.Popen([exe, "-D", str(DDSPERF_SECONDS + 2), "-i", str(domain), "pong"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    try:
        ping = subprocess.run([exe, "-D", str(DDSPERF_SECONDS), "-i", str(domain), "ping",
                               DDSPERF_RATE], capture_output=True, text=True, env=env,
                              timeout=DDSPERF_SECONDS + 30)
    finally:
        pong.terminate()
        try:
            pong.wait(10)
        except subprocess.TimeoutExpired:
            pong.kill()
            pong.wait()
    return parse_ddsperf(ping.stdout)


def measure(samples: int = DEFAULT_SAMPLES, progress=None) -> dict:
    """Runs both measurements; `progress(text)` is told what runs next."""
    say = progress or (lambda text: None)
    domain = dds.domain_for_run()
    try:
        with tempfile.TemporaryDirectory(prefix="ima-bench-dds-") as tmp:
            say(f"cross-channel exchange through two agents: {samples} rounds")
            ours = _product_latency(domain, samples, Path(tmp))
            say(f"ddsperf ping/pong at {DDSPERF_RATE}: {DDSPERF_SECONDS} s")
            ref = _ddsperf_latency(domain)
    finally:
        dds.release_domain(domain)
    result = {
        "dds_latency_us_median": ours["median_us"],
        "dds_latency_us_p95": ours["p95_us"],
        "dds_latency_us_min": ours["min_us"],
        "dds_latency_samples": ours["samples"],
        "dds_latency_incomplete": ours["incomplete"],
        "dds_latency_measure": "one-way, io B INPUTS -> io A AGREED through both agents, "
                               "one process's CLOCK_MONOTONIC",
        "ddsperf_latency_us_median": ref["median"],
        "ddsperf_latency_us_p90": ref["p90"],
        "ddsperf_samples": ref["count"],
        "ddsperf_measure": f"round trip / 2, ddsperf ping {DDSPERF_RATE} / pong",
        "ratio": round(ours["median_us"] / ref["median"], 2) if ref["median"] else None,
        "domain": domain,
        "config": str(dds.config_path()),
        "cpus": os.cpu_count(),
    }
    return result


def run(json_out: bool = False, samples: int = DEFAULT_SAMPLES) -> int:
    """Runs the benchmark, prints JSON if `json_out` (else a table); exit code."""
    from rich.console import Console

    err = Console(stderr=True)
    if json_out:
        with err.status("benchmarking the DDS link") as status:
            result = measure(samples, progress=lambda text: status.update(text))
        json.dump(result, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    out = Console()
    with out.status("benchmarking the DDS link") as status:
        result = measure(samples, progress=lambda text: status.update(text))
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
    args = parser.parse_args(argv)
    try:
        return run(json_out=args.json, samples=args.samples)
    except ImaError as e:
        print(f"ima.bench.dds: {e}", file=sys.stderr)
        return e.exit_code


if __name__ == "__main__":
    sys.exit(main())
