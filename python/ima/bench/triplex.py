# SPDX-License-Identifier: Apache-2.0
"""`ima bench triplex`: the redundant system at work.

- speedup, speedup_pinned, aggregate_speedup, cpu_ms_per_emulated_s, floor: a 10-minute flight
  of config/systems/rpas_triplex.yaml (3 nodes, each an SKE with its partitions and a DDS
  agent, the CAN bus, the world) by `ima launch` with its defaults, flown three ways as
  `ima bench flight` flies its own (ima.bench.flight); truth_identical_to_reference: its
  truth against the one recorded before the lockstep was made cheaper;
- peak_rss_mb: the peak of the summed resident memory of every process of that run;
- dds_latency_us_median: node-to-node latency of DDS between two of the product's agents in
  real-time mode (one agent's dds_write to the other's take), next to
  ddsperf_latency_us_median measured in the same run with ddsperf on the same Cyclone
  configuration; xch_latency_us_median: the whole cross-channel path from one node's io
  partition to the other's, which adds the two partition-to-agent hops inside the nodes
  (ima.bench.dds says how each is measured);
- dds_latency_secure_us_median and ddsperf_secure_latency_us_median: the same two with DDS
  Security as runs have it by default (secure_latency_ratio, target ≤ 2 as well)."""

from __future__ import annotations

import json
from pathlib import Path

from ima import paths
from ima.bench.flight import measure_flight, print_speeds

TARGETS = {"speedup": 20.0, "speedup_pinned": 75.0, "aggregate_speedup": 150.0,
           "latency_ratio": 2.0, "peak_rss_mb": 600.0}
# The SHA-256 of truth.jsonl of the default triplex flight (600 s, seed 1, the default pilot,
# light turbulence, 10 kt wind), recorded before the lockstep was made cheaper: a change of the
# lockstep must leave it byte-identical (docs/performance.md).
REFERENCE_TRUTH_SHA256 = "5035efa84aa69c0c541add771b961b3c07599f2a39fb94da34b20e358e7a6d0f"


def default_system() -> Path:
    return paths.repo_root() / "config" / "systems" / "rpas_triplex.yaml"


def run(json_out: bool, duration_s: float = 600.0, seed: int = 1,
        system: Path | None = None, dds_security: str = "sign") -> int:
    from rich.console import Console

    from ima.bench import dds as dds_bench

    console = Console(stderr=True)
    results = measure_flight(system or default_system(), duration_s, seed, console)
    with console.status("DDS latency: two agents in real time, then ddsperf") as status:
        lat = dds_bench.measure(progress=lambda text: status.update(f"DDS latency {text}"),
                                secure_mode=dds_security)
    results["dds_latency_us_median"] = lat.get("dds_latency_us_median")
    results["ddsperf_latency_us_median"] = lat.get("ddsperf_latency_us_median")
    results["xch_latency_us_median"] = lat.get("xch_latency_us_median")
    ours, ref = results["dds_latency_us_median"], results["ddsperf_latency_us_median"]
    results["dds_latency_secure_us_median"] = lat.get("dds_latency_secure_us_median")
    results["ddsperf_secure_latency_us_median"] = lat.get("ddsperf_secure_latency_us_median")
    results["secure_latency_ratio"] = lat.get("secure_ratio")
    results["dds_security"] = lat.get("security")
    results["latency_ratio"] = lat.get("ratio")
    results["xch_latency_ratio"] = lat.get("xch_ratio")
    results["dds_bench"] = lat
    if duration_s == 600.0 and seed == 1 and system is None:
        results["truth_identical_to_reference"] = \
            results["truth_sha256"] == REFERENCE_TRUTH_SHA256
    results["targets_met"] = {
        "speedup": results["speedup"] >= TARGETS["speedup"],
        "speedup_pinned": results["speedup_pinned"] >= TARGETS["speedup_pinned"],
        "aggregate_speedup": results["aggregate_speedup"] >= TARGETS["aggregate_speedup"],
        "dds_latency": results["latency_ratio"] is not None
        and results["latency_ratio"] <= TARGETS["latency_ratio"],
        "dds_latency_secure": results["secure_latency_ratio"] is not None
        and results["secure_latency_ratio"] <= TARGETS["latency_ratio"],
        "peak_rss_mb": results["peak_rss_mb"] < TARGETS["peak_rss_mb"],
    }
    if json_out:
        print(json.dumps(results))
    else:
        out = Console()
        out.print(f"triplex flight: {results['flight_s']:.0f} s emulated in "
                  f"{results['wall_s']:.1f} s wall → speed-up ×{results['speedup']:.0f} "
                  f"(target ≥ {TARGETS['speedup']:.0f})")
        print_speeds(out, results, TARGETS)
        if "truth_identical_to_reference" in results:
            out.print("truth of the default flight: " + (
                "byte-identical to the reference" if results["truth_identical_to_reference"]
                else "[red]differs from the reference[/red]"))
        out.print(f"node-to-node DDS latency: median {ours} µs; ddsperf on the same config: "
                  f"{ref} µs; ratio {results['latency_ratio']} "
                  f"(target ≤ {TARGETS['latency_ratio']:g}×)")
        out.print(f"with DDS Security ({results['dds_security']}): median "
                  f"{results['dds_latency_secure_us_median']} µs; ddsperf with the same "
                  f"settings: {results['ddsperf_secure_latency_us_median']} µs; ratio "
                  f"{results['secure_latency_ratio']} (target ≤ {TARGETS['latency_ratio']:g}×)")
        out.print(f"io-to-io cross-channel exchange: median {results['xch_latency_us_median']} µs "
                  f"({results['xch_latency_ratio']}× ddsperf)")
        out.print(f"peak memory of the whole run: {results['peak_rss_mb']:.0f} MB "
                  f"(target < {TARGETS['peak_rss_mb']:.0f})")
    return 0
