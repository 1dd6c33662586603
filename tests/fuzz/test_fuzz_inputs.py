# SPDX-License-Identifier: Apache-2.0
"""The product's inputs, mutated (tests/fuzz/mutate.py, seeded): module files, system models,
pilot scripts and campaign files. For each input: exit 0 or the documented error with one
clear line; no traceback, no signal, done within its time limit, nothing written outside the
folder it was given. Valid inputs are run (a module 20 major frames; a pilot script or a
system model flown 1.2 s, 20 frames and more), so the fuzzing reaches past the parsers; at
least a quarter of the inputs must have run.

IMA_FUZZ_COUNT sets the number of inputs (default 400, a minute or so);
`./ima test --fuzz-long` runs 10,000 and writes its counts to IMA_FUZZ_REPORT."""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
import time
import traceback
from collections import Counter
from pathlib import Path

import pytest
import yaml

from ima.campaign import spec as campaign_spec
from ima.deploy import generate, load_system
from ima.deploy.source import read_source
from ima.errors import ImaError
from imaworld import pilot as pilot_script

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mutate  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("IMA_BUILD_DIR", ROOT / "build"))
SKE = BUILD / "ske" / "ima-ske"
PARTITIONS = BUILD / "partitions"
COUNT = int(os.environ.get("IMA_FUZZ_COUNT", "400"))
SEED = int(os.environ.get("IMA_FUZZ_SEED", "653"))
# Shares of the inputs, and of the valid pilot scripts and system models flown (a flight
# costs about a second and a half; a module's 20 frames a tenth of one).
SHARES = {"module": 0.55, "pilot": 0.2, "system": 0.15, "campaign": 0.1}
FLY = {"pilot": 0.25, "system": 0.08}
TIME_LIMIT_S = 60.0


class Tally:
    def __init__(self) -> None:
        self.counts: Counter = Counter()
        self.problems: list[str] = []

    def problem(self, kind: str, k: int, what: str, path: Path) -> None:
        keep = path.parent / "kept"
        keep.mkdir(exist_ok=True)
        kept = keep / f"{kind}-{k}{path.suffix}"
        kept.write_bytes(path.read_bytes())
        self.problems.append(f"{kind} #{k} ({kept}): {what}")


def _run(cmd: list[str], cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    try:
        return subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, timeout=TIME_LIMIT_S,
                              env=env, errors="replace")
    except subprocess.TimeoutExpired:
        return subprocess.CompletedProcess(cmd, -999, "", "time limit")


def _judge_process(p: subprocess.CompletedProcess, allowed: set[int]) -> str | None:
    """What is wrong with how a process ended, or None."""
    if p.returncode == -999:
        return f"not done within {TIME_LIMIT_S:g} s"
    if p.returncode < 0 or p.returncode >= 128:
        return f"ended by a signal ({p.returncode})"
    if "Traceback" in p.stderr or "AddressSanitizer" in p.stderr:
        return "a traceback: " + p.stderr[-800:]
    if p.returncode not in allowed:
        return f"exit status {p.returncode} (documented: {sorted(allowed)}): {p.stderr[-400:]}"
    if p.returncode == 2 and len([x for x in p.stderr.splitlines() if x.strip()]) != 1:
        return "not one clear line: " + p.stderr[-800:]
    return None


def _in_process(call, expected=(ImaError,)) -> tuple[bool, str | None]:
    """(valid, what is wrong): an expected error is a clear refusal; anything else is not."""
    try:
        call()
    except expected:
        return False, None
    except Exception:  # noqa: BLE001 - every other exception is what the fuzzing looks for
        return False, traceback.format_exc(limit=4)[-1500:]
    return True, None


def _read(kind: str, k: int, path: Path, call, tally: Tally) -> bool:
    """An input read in this process: counted, its problem kept; whether it is valid."""
    valid, wrong = _in_process(call)
    tally.counts[kind] += 1
    tally.counts[f"valid_{kind}"] += valid
    if wrong:
        tally.problem(kind, k, wrong, path)
    return valid


def _flat(system: Path) -> dict:
    src = read_source(system)
    doc = json.loads(json.dumps(src.doc, default=str))
    ch = doc["channels"]
    base = src.base("channels")
    ch["can"]["dbc"] = str((base / ch["can"]["dbc"]).resolve())
    ch["dds"]["config"] = str((base / ch["dds"]["config"]).resolve())
    return doc


def _campaign(path: Path) -> str:
    """A campaign file with its paths absolute (its copies are written elsewhere)."""
    doc = yaml.safe_load(path.read_text())
    doc["system"] = str((path.parent / doc["system"]).resolve())
    for w in doc["workloads"].values():
        w["pilot"] = str((path.parent / w["pilot"]).resolve())
    return yaml.safe_dump(doc, sort_keys=False)


def _fuzz_module(rng, k, work, cwd, tally, seeds):
    text = rng.choice(seeds)
    new = mutate.mutate_text_mild(rng, text) if rng.random() < 0.6 else \
        mutate.mutate_text(rng, text)
    if new in seeds:
        tally.counts["module_same_as_seed"] += 1
        return
    path = work / f"module-{k}.xml"
    path.write_text(new, encoding="utf-8", errors="surrogatepass")
    env = dict(os.environ, IMA_PARTITION_PATH=str(PARTITIONS))
    p = _run([str(SKE), "--check", "--", str(path)], cwd, env)
    wrong = _judge_process(p, {0, 2})
    if wrong:
        tally.problem("module", k, wrong, path)
        return
    tally.counts["module"] += 1
    if p.returncode != 0:
        return
    tally.counts["valid_module"] += 1
    stats = work / f"module-{k}.stats.json"
    p = _run([str(SKE), "--frames", "20", "--stats", str(stats), "--", str(path)], cwd, env)
    wrong = _judge_process(p, {0, 1, 3})
    if wrong:
        tally.problem("module-run", k, wrong, path)
        return
    try:
        frames = json.loads(stats.read_text()).get("frames", 0)
    except (OSError, ValueError):
        frames = 0
    if frames >= 20:
        tally.counts["ran"] += 1


def _fuzz_pilot(rng, k, work, cwd, tally, seeds):
    text = rng.choice(seeds)
    if rng.random() < 0.8:
        new = yaml.safe_dump(mutate.mutate_doc(rng, yaml.safe_load(text), rng.random() < 0.6),
                             sort_keys=False, allow_unicode=True)
    else:
        new = mutate.mutate_text(rng, text)
    if new in seeds:
        return
    path = work / f"pilot-{k}.yaml"
    path.write_text(new, encoding="utf-8", errors="surrogatepass")
    valid = _read("pilot", k, path, lambda: pilot_script.load(path), tally)
    if valid and rng.random() < FLY["pilot"]:
        _fly(["fly", "--pilot", str(path)], "pilot", k, path, work, cwd, tally)


def _fuzz_system(rng, k, work, cwd, tally, seeds):
    doc = rng.choice(seeds)
    new = mutate.mutate_doc(rng, doc, rng.random() < 0.6)
    if new in seeds:
        return
    path = work / f"system-{k}.yaml"
    path.write_text(yaml.safe_dump(new, sort_keys=False, allow_unicode=True), encoding="utf-8")
    out = work / f"system-{k}-deploy"
    valid = _read("system", k, path, lambda: generate(load_system(path), out), tally)
    if valid and rng.random() < FLY["system"]:
        _fly(["launch", str(path)], "system", k, path, work, cwd, tally)


def _fly(args: list[str], kind: str, k: int, path: Path, work: Path, cwd: Path, tally) -> None:
    """A valid input flown 1.2 s (20 major frames and more): `ima fly` or `ima launch`."""
    p = _run([str(ROOT / "ima"), *args, "--duration", "1.2", "--run-dir",
              str(work / f"{kind}-{k}-run"), "--json"], cwd)
    wrong = _judge_process(p, {0, 1, 2})
    if wrong:
        tally.problem(f"{kind}-flight", k, wrong, path)
    elif p.returncode == 0 and json.loads(p.stdout).get("flown_s", 0) >= 1.0:
        tally.counts["ran"] += 1


def _fuzz_campaign(rng, k, work, cwd, tally, seeds):
    text = rng.choice(seeds)
    new = yaml.safe_dump(mutate.mutate_doc(rng, yaml.safe_load(text), rng.random() < 0.5),
                         sort_keys=False, allow_unicode=True) if rng.random() < 0.8 \
        else mutate.mutate_text(rng, text)
    path = work / f"campaign-{k}.yaml"
    path.write_text(new, encoding="utf-8", errors="surrogatepass")
    _read("campaign", k, path, lambda: campaign_spec.load(path), tally)


@pytest.mark.skipif(not SKE.is_file(), reason="ima-ske is not built")
def test_no_input_crashes_hangs_or_shows_a_traceback(tmp_path):
    rng = random.Random(SEED)
    work, cwd = tmp_path / "inputs", tmp_path / "cwd"
    work.mkdir()
    cwd.mkdir()
    seeds = {
        "module": [(ROOT / "config" / "examples" / "three_partitions.xml").read_text()],
        "pilot": [p.read_text() for p in sorted((ROOT / "sim" / "pilots").glob("*.yaml"))],
        "system": [_flat(ROOT / "config" / "systems" / f"rpas_{n}.yaml")
                   for n in ("simplex", "triplex")],
        "campaign": [_campaign(ROOT / "config" / "campaigns" / "smoke.yaml")],
    }
    fuzz = {"module": _fuzz_module, "pilot": _fuzz_pilot, "system": _fuzz_system,
            "campaign": _fuzz_campaign}
    tally = Tally()
    t0 = time.monotonic()
    kinds = list(SHARES)
    for k in range(COUNT):
        kind = rng.choices(kinds, weights=[SHARES[x] for x in kinds])[0]
        fuzz[kind](rng, k, work, cwd, tally, seeds[kind])
    generated = sum(tally.counts[x] for x in SHARES)
    report = {"inputs": generated, "ran": tally.counts["ran"],
              "by_kind": {x: tally.counts[x] for x in SHARES},
              "valid": {x: tally.counts[f"valid_{x}"] for x in SHARES},
              "problems": len(tally.problems),
              "seed": SEED, "wall_s": round(time.monotonic() - t0, 1)}
    print(json.dumps(report))
    if os.environ.get("IMA_FUZZ_REPORT"):
        Path(os.environ["IMA_FUZZ_REPORT"]).write_text(json.dumps(report, indent=1) + "\n")
    assert not tally.problems, "\n".join(tally.problems[:10])
    assert list(cwd.iterdir()) == [], "written outside the folders given"
    assert report["ran"] >= generated / 4, report
