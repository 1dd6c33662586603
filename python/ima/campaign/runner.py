# SPDX-License-Identifier: Apache-2.0
"""Runs a campaign into its folder: the derived systems, the golden runs (once per workload
and seed, cached in the folder), then every run in parallel — one flight per CPU, each pinned
to its CPU, on this machine, or on a Dask cluster — appending one line per finished run to
results.jsonl (a crash or Ctrl-C loses nothing; --resume skips what is done), with a live
progress bar; then the report."""

from __future__ import annotations

import json
import multiprocessing
import os
import shutil
import time
from collections import Counter
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path

import yaml

from ima.campaign import job, spec, systems
from ima.errors import ImaError

RESULTS = "results.jsonl"


@dataclass
class RunnerOptions:
    out: Path
    jobs: int
    resume: bool = False
    keep_all: bool = False
    executor: str = "local"  # local | dask
    scheduler: str | None = None  # dask: tcp://HOST:PORT; None: a LocalCluster on loopback
    test_switches: tuple[str, ...] = ()
    argv: tuple[str, ...] = ()


def campaign_data(c: spec.Campaign, opts: RunnerOptions) -> dict:
    """What every job needs, as plain data (Dask ships it to its workers)."""
    return {
        "name": c.name, "dir": str(opts.out.resolve()), "system": str(c.system),
        "duration_s": c.duration_s, "keep_all": opts.keep_all, "argv": list(opts.argv),
        "test_switches": list(opts.test_switches),
        "workloads": {w.name: {"name": w.name, "pilot": str(w.pilot), "turbulence": w.turbulence,
                               "wind_kt": w.wind_kt, "mission_feed": w.mission_feed,
                               "mission": None if w.mission is None else str(w.mission)}
                      for w in c.workloads.values()},
        "golden_of": {r.run_id: spec.golden_key(c, r) for r in c.runs},
    }


def drop_cut_line(out: Path) -> None:
    """A results.jsonl whose last line a crash cut short loses that line (its run is flown
    again), so that the next record starts a line of its own."""
    path = out / RESULTS
    try:
        data = path.read_bytes()
    except OSError:
        return
    if data and not data.endswith(b"\n"):
        path.write_bytes(data[:data.rfind(b"\n") + 1])


def done_ids(out: Path) -> set[str]:
    ids = set()
    try:
        with open(out / RESULTS, encoding="utf-8") as f:
            for line in f:
                try:
                    ids.add(json.loads(line)["run_id"])
                except (ValueError, KeyError):
                    continue  # a line cut by a crash: that run is flown again
    except OSError:
        pass
    return ids


def append(out: Path, record: dict) -> None:
    """One line, flushed to the disk before the next run is counted."""
    with open(out / RESULTS, "a", encoding="utf-8") as f:
        f.write(json.dumps(record, sort_keys=True) + "\n")
        f.flush()
        os.fsync(f.fileno())


# ---- jobs, as a worker runs them ------------------------------------------------------------

_CPU = None


def _pin(counter, cpus: list[int]) -> None:
    """Pins this worker (and the processes of its flights) to one CPU of its own."""
    global _CPU
    with counter.get_lock():
        k = counter.value
        counter.value += 1
    _CPU = cpus[k % len(cpus)]
    try:
        os.sched_setaffinity(0, {_CPU})
    except (AttributeError, OSError):
        pass


def fly_golden(campaign: dict, key: str, run: dict) -> str:
    from ima.launch.judging import fly_golden as fly

    gdir = Path(campaign["dir"]) / "golden" / key
    if (gdir / "done").is_file():
        return key
    shutil.rmtree(gdir, ignore_errors=True)
    opts = job.options(campaign, run, gdir, [])
    opts.test_switches = []
    fly(opts, gdir)
    (gdir / "done").write_text("")
    return key


def run_job(campaign: dict, run: dict) -> dict:
    record = job.run_one(campaign, run)
    record["worker"] = {"pid": os.getpid(), "cpu": _CPU}
    return record


# ---- executors --------------------------------------------------------------------------------

class _Local:
    def __init__(self, jobs: int) -> None:
        cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else [0]
        ctx = multiprocessing.get_context("spawn")
        self.pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_pin,
                                        initargs=(ctx.Value("i", 0), cpus))

    def submit(self, fn, *args):
        return self.pool.submit(fn, *args)

    def wait(self, futures):
        done, _ = wait(futures, timeout=0.5, return_when=FIRST_COMPLETED)
        return done

    def close(self, cancel: bool = False) -> None:
        self.pool.shutdown(wait=not cancel, cancel_futures=cancel)


class _Dask:
    def __init__(self, jobs: int, scheduler: str | None) -> None:
        from distributed import Client, LocalCluster

        self.cluster = None
        if scheduler is None:
            self.cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                                        host="127.0.0.1", dashboard_address=None)
            scheduler = self.cluster.scheduler_address
        self.client = Client(scheduler)

    def submit(self, fn, *args):
        return self.client.submit(fn, *args, pure=False)

    def wait(self, futures):
        from distributed import wait as dwait

        try:
            done, _ = dwait(list(futures), timeout=0.5, return_when="FIRST_COMPLETED")
        except TimeoutError:  # distributed's wait raises when nothing finished in time
            return set()
        return done

    def close(self, cancel: bool = False) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _executor(opts: RunnerOptions):
    if opts.executor == "dask":
        return _Dask(opts.jobs, opts.scheduler)
    return _Local(opts.jobs)


def prepare(c: spec.Campaign, opts: RunnerOptions) -> dict:
    out = opts.out
    if (out / RESULTS).exists() and not opts.resume:
        raise ImaError(f"{out} already holds a campaign's results: --resume to go on with it, "
                       "or another --out", exit_code=2)
    doc = spec.resolved_doc(c)
    if opts.resume and (out / "campaign.json").is_file():
        try:
            before = json.loads((out / "campaign.json").read_text())
        except (OSError, ValueError):
            before = {}
        if before.get("doc", doc) != doc or before.get("runs") != [r.to_json() for r in c.runs]:
            raise ImaError(f"{out}: planned with another version of {c.path.name} (its "
                           "content or its runs differ); resume with the campaign as it was, "
                           "or use another --out", exit_code=2)
    out.mkdir(parents=True, exist_ok=True)
    (out / "runs").mkdir(exist_ok=True)
    (out / "campaign.yaml").write_text(
        f"# {c.path}, as this campaign ran it (its paths made absolute)\n" +
        yaml.safe_dump(spec.resolved_doc(c), sort_keys=False), encoding="utf-8")
    data = campaign_data(c, opts)
    for w in c.workloads.values():
        if w.mission_feed:
            systems.with_mission_feed(c.system, out / "systems" / f"{w.name}.yaml",
                                      w.mission_feed)
    (out / "campaign.json").write_text(json.dumps(
        {"campaign": c.name, "file": str(c.path), "system": str(c.system),
         "duration_s": c.duration_s, "doc": doc, "runs": [r.to_json() for r in c.runs]},
        indent=1) + "\n")
    return data


def run(c: spec.Campaign, opts: RunnerOptions, progress=None) -> list[dict]:
    """Every run of the campaign not yet done; returns every record of results.jsonl."""
    data = prepare(c, opts)
    if opts.resume:
        drop_cut_line(opts.out)
    done = done_ids(opts.out) if opts.resume else set()
    todo = [r for r in c.runs if r.run_id not in done]
    goldens = {}
    for r in todo:
        goldens.setdefault(data["golden_of"][r.run_id], r)
    ex = _executor(opts)
    counts: Counter = Counter()
    t0 = time.monotonic()
    try:
        pending = {ex.submit(fly_golden, data, k, r.to_json()): ("golden", k)
                   for k, r in goldens.items()}
        if progress:
            progress.start(len(goldens), len(todo), len(done))
        while pending:
            for fut in ex.wait(set(pending)):
                pending.pop(fut)
                fut.result()
                if progress:
                    progress.golden_done()
        # grouped by golden run: a worker keeps the last golden run it read (judge.py)
        todo.sort(key=lambda r: data["golden_of"][r.run_id])
        pending = {ex.submit(run_job, data, r.to_json()): ("run", r.run_id) for r in todo}
        while pending:
            for fut in ex.wait(set(pending)):
                _, run_id = pending.pop(fut)
                record = fut.result()
                append(opts.out, record)
                counts[record["measures"]["outcome"]] += 1
                if record["measures"]["oracle_violations"]:
                    counts["violations"] += 1
                if progress:
                    progress.run_done(record, counts, time.monotonic() - t0)
    except BaseException:
        ex.close(cancel=True)
        raise
    ex.close()
    return read_results(opts.out)


def read_results(out: Path) -> list[dict]:
    records = []
    with open(out / RESULTS, encoding="utf-8") as f:
        for line in f:
            try:
                records.append(json.loads(line))
            except ValueError:
                continue
    return sorted(records, key=lambda r: r["run_id"])
