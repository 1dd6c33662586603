# SPDX-License-Identifier: Apache-2.0
"""A campaign file (config/campaigns/*.yaml, config/schema/campaign.schema.json), checked and
expanded into its runs: each fault entry over its targets, times, workloads, seeds and
repetitions; targets and times drawn with the campaign's own seed, so the same file always
gives the same runs."""

from __future__ import annotations

import functools
import json
import random
import re
from dataclasses import asdict, dataclass, field
from pathlib import Path

import jsonschema
import yaml

from faultinject import catalogue, grammar
from ima import paths, yamlfile
from ima.errors import ImaError


class CampaignError(ImaError):
    def __init__(self, message: str) -> None:
        super().__init__(message, exit_code=2)


@dataclass(frozen=True)
class Workload:
    name: str
    pilot: Path
    turbulence: str = "light"
    wind_kt: float = 10.0
    mission_feed: dict | None = None
    mission: Path | None = None  # a plan the mission manager flies (uplinked at run time)


@dataclass(frozen=True)
class RunSpec:
    """One run of a campaign."""

    run_id: str
    group: str  # the fault class, or the name of a multi-fault entry
    classes: tuple[str, ...]
    faults: tuple[str, ...]  # short forms; ids f1, f2, ... in order
    workload: str
    seed: int
    weight: float = 1.0
    realtime: bool = False  # flown with --realtime (and so is its golden run)

    def to_json(self) -> dict:
        return asdict(self)


@dataclass
class Campaign:
    name: str
    path: Path
    system: Path
    duration_s: float
    seeds: list[int]
    seed: int
    repetitions: int
    workloads: dict[str, Workload]
    runs: list[RunSpec] = field(default_factory=list)
    doc: dict = field(default_factory=dict)


@functools.cache
def _schema() -> dict:
    path = paths.repo_root() / "config" / "schema" / "campaign.schema.json"
    return json.loads(path.read_text(encoding="utf-8"))


def _file(base: Path, text: str, what: str) -> Path:
    p = Path(text)
    p = p if p.is_absolute() else (base / p).resolve()
    if not p.is_file():
        raise CampaignError(f"{what}: no such file: {p}")
    return p


def load(path: Path) -> Campaign:
    """A campaign and its runs; CampaignError naming the bad path in the file."""
    try:
        doc = yamlfile.load(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise CampaignError(f"{path}: cannot read: {exc}") from exc
    except yamlfile.YamlLimitError as exc:
        raise CampaignError(f"{path}: refused: {exc}") from exc
    except yaml.YAMLError as exc:
        raise CampaignError(f"{path}: not valid YAML: {exc}") from exc
    e = grammar.first_schema_error(jsonschema.Draft202012Validator(_schema()), doc)
    if e is not None:
        raise CampaignError(f"{path}: {e}")
    base = Path(path).resolve().parent
    workloads = {}
    for name, w in doc["workloads"].items():
        if "mission" in w and "mission_feed" in w:
            raise CampaignError(f"{path}: workloads.{name}: a plan (mission) or the stand-in "
                                "feed (mission_feed), not both")
        plan = None
        if "mission" in w:
            plan = _file(base, w["mission"], f"{path}: workloads.{name}.mission")
            _check_plan(plan, f"{path}: workloads.{name}.mission")
        workloads[name] = Workload(name, _file(base, w["pilot"], f"{path}: workloads.{name}.pilot"),
                                   w.get("turbulence", "light"), float(w.get("wind_kt", 10.0)),
                                   w.get("mission_feed"), plan)
    c = Campaign(name=doc["campaign"], path=Path(path).resolve(),
                 system=_file(base, doc["system"], f"{path}: system"),
                 duration_s=float(doc["duration_s"]), seeds=list(doc["seeds"]),
                 seed=int(doc.get("seed", 1)), repetitions=int(doc.get("repetitions", 1)),
                 workloads=workloads, doc=doc)
    c.runs = expand(c)
    return c


def _check_plan(plan: Path, where: str) -> None:
    """A workload's mission plan must load and fit the uplink (ima mission check)."""
    from ima.mission import image
    from ima.mission import plan as mission_plan

    try:
        image.encode(mission_plan.load(plan))
    except ImaError as exc:
        raise CampaignError(f"{where}: {exc}") from exc


def targets_of(system, cls: str) -> list[str]:
    """Every WHERE a class can act on in the system."""
    fc = catalogue.get(cls)
    nodes = [n.name for n in system.nodes]
    if fc.target in ("world", "bus"):
        return [fc.target]
    if fc.target in ("node", "client"):
        return nodes
    out = []
    for node in nodes:
        for p in system.partitions:
            if fc.target == "partition":
                out.append(f"{p.name}@{node}")
            elif fc.target == "process":
                out += [f"{p.name}.{pr.name}@{node}" for pr in p.processes]
            else:
                out += [f"{p.name}.{po.name}@{node}" for po in p.ports if po.is_source and
                        (cls != "queuing_flood" or po.kind == "queuing")]
    return out


def _systems(c: Campaign) -> dict:
    """The system each workload flies: the campaign's, or the one derived from it with the
    mission feed (built in a scratch folder here, to check the faults' targets against)."""
    import tempfile

    from ima.deploy import load_system

    from . import systems as derived

    base = load_system(c.system)
    out = {}
    with tempfile.TemporaryDirectory(prefix="ima-campaign-") as tmp:
        for name, w in c.workloads.items():
            out[name] = base if not w.mission_feed else load_system(
                derived.with_mission_feed(c.system, Path(tmp) / f"{name}.yaml", w.mission_feed))
    return out


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-").lower()


def _times(at, rng: random.Random, n: int) -> list[float]:
    if isinstance(at, dict):
        lo, hi = at["uniform"]
        return [round(rng.uniform(lo, hi), 2) for _ in range(n)]
    return [float(at)] * n


def expand(c: Campaign) -> list[RunSpec]:
    """The campaign's runs, in a fixed order; every fault spec checked (grammar, catalogue,
    the system's targets)."""
    from faultinject.plan import check_target

    systems = _systems(c)
    runs: list[RunSpec] = []
    for i, entry in enumerate(c.doc["faults"]):
        where = f"{c.path}: faults[{i}]"
        rng = random.Random(f"{c.seed}/{i}")
        loads = entry.get("workloads") or list(c.workloads)
        for w in loads:
            if w not in c.workloads:
                raise CampaignError(f"{where}: no workload '{w}' (workloads: "
                                    f"{', '.join(c.workloads)})")
        weight = float(entry.get("weight", 1.0))
        realtime = bool(entry.get("realtime", False))
        if "specs" in entry:
            groups = [(entry["name"], tuple(entry["specs"]))]
            classes = None
        else:
            cls = entry["class"]
            try:
                catalogue.get(cls)
            except ImaError as exc:
                raise CampaignError(f"{where}: {exc}") from None
            sel = entry.get("targets", "all")
            # what every workload of the entry can be hit on (a workload that flies the
            # stand-in mission feed has no mission manager)
            pool = [t for t in targets_of(systems[loads[0]], cls)
                    if all(t in targets_of(systems[w], cls) for w in loads[1:])]
            if sel == "all":
                wheres = pool
            elif isinstance(sel, dict):
                wheres = sorted(rng.sample(pool, min(sel["sample"], len(pool))), key=pool.index)
            else:
                wheres = list(sel)
            dur = f"~{entry['duration']}" if entry.get("duration") else ""
            params = ",".join(f"{k}={v}" for k, v in (entry.get("params") or {}).items())
            groups = []
            for wh in wheres:
                for t in _times(entry["at_s"], rng, int(entry.get("times", 1))):
                    spec = f"{wh}:{cls}@{t:g}{dur}" + (f":{params}" if params else "")
                    groups.append((cls, (spec,)))
            classes = cls
        for group, specs in groups:
            faults = []
            try:
                faults = [grammar.parse(s, f"f{k}") for k, s in enumerate(specs, start=1)]
                grammar.check_ids(faults, where)
                for f in faults:
                    for w in loads:
                        check_target(systems[w], f)
                    if f.trigger.at_s is not None and not f.trigger.at_s < c.duration_s:
                        raise CampaignError(f"{where}: {f.spec()}: after the end of the flights "
                                            f"({c.duration_s:g} s)")
            except ImaError as exc:
                raise CampaignError(f"{where}: {exc}") from None
            for w in loads:
                for seed in c.seeds:
                    for rep in range(c.repetitions):
                        n = len(runs) + 1
                        tag = _slug(specs[0].split(":")[0]) if classes else group
                        run_id = f"{n:04d}-{classes or group}-{tag}-{w}-s{seed}" + \
                            ("-rt" if realtime else "") + \
                            (f"-r{rep + 1}" if c.repetitions > 1 else "")
                        runs.append(RunSpec(run_id, classes or group,
                                            tuple(f.cls for f in faults), tuple(specs), w, seed,
                                            weight, realtime))
    if not runs:
        raise CampaignError(f"{c.path}: no runs")
    return runs


def resolved_doc(c: Campaign) -> dict:
    """The campaign file's content with its paths made absolute: the copy a campaign folder
    keeps (campaign.yaml), which `--resume` and `rerun` load wherever the folder is."""
    doc = dict(c.doc, system=str(c.system))
    doc["workloads"] = {}
    for name, w in c.doc["workloads"].items():
        doc["workloads"][name] = dict(w, pilot=str(c.workloads[name].pilot))
        if c.workloads[name].mission is not None:
            doc["workloads"][name]["mission"] = str(c.workloads[name].mission)
    return doc


def golden_key(c: Campaign, run: RunSpec) -> str:
    """Runs share a golden run when they share system, workload, seed and time mode (and
    duration)."""
    return f"{run.workload}-s{run.seed}" + ("-rt" if run.realtime else "")

