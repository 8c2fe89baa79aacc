"""``semsearch bench run`` and the bench's side of ``semsearch verify``.

A bench results folder holds ``bench.json`` (the suite, split, its hash, the numbering, the
planners run into it) and one sub-folder per floor, each an ordinary results folder (runs.csv,
meta.json, decisions/) beside ``scenario/``: the floor as it was run (its labels permuted under a
numbering other than ``true``). Every run is recorded with its decisions, and every row carries
the suite, split, hash, numbering and floor (:data:`~semsearch_cli.metrics.BENCH_COLUMNS`).
Floors run one after the other, each a resumable batch: an interrupted bench run resumes where it
stopped, whatever the workers or the executor.
"""

from __future__ import annotations

import csv
import json
import os
from contextlib import nullcontext
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from ..config import PlannerSpec
from ..config.base import sign_label
from ..errors import ScenarioError, did_you_mean
from ..files import atomic_text, output_folder
from ..report.build import write_meta
from ..metrics import outside_the_run
from ..planners.base import expand_variants, preflight
from ..runner import Batch, BatchOptions, Loaded, folder_lock, make_executor, read_runs
from ..runner.batch import BENCH_FILE as _BENCH_MARK
from ..runner.specs import RunList
from ..runner.verify import Verdict, check_folder_engine, verify_folder
from ..tasks.episodes import Episode
from .numbering import NUMBERINGS, relabel
from .predictability import predictability
from .suites import Floor, Split, open_split, suite_named

BENCH_FILE = _BENCH_MARK  # one name, which the runner refuses a plain run into (runner.batch)


def _copy_named(doc, base: Path, dest: Path):
    """``doc`` with every string that names a file beside the floor's scenario (its map, signs,
    rooms, episodes, logs) copied into ``dest`` and renamed to the copy (its file name)."""
    if isinstance(doc, dict):
        return {k: _copy_named(v, base, dest) for k, v in doc.items()}
    if isinstance(doc, list):
        return [_copy_named(v, base, dest) for v in doc]
    if isinstance(doc, str) and doc and "/" not in doc and (base / doc).is_file():
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(base / doc, dest / doc)
    return doc


def materialise(split: Split, floor: Floor, numbering: str, dest: Path) -> Path:
    """Write ``floor`` into ``dest`` as it runs under ``numbering``: its scenario and every file
    it names, the signs' labels (and the goals and episodes with them) permuted by
    :func:`~.numbering.relabel`. Returns the scenario's path."""
    if numbering not in NUMBERINGS:
        raise ScenarioError("<command line>", "--numbering", unknown_numbering(numbering))
    src = floor.scenario
    dest.mkdir(parents=True, exist_ok=True)
    doc = _copy_named(yaml.safe_load(src.read_text()), src.parent, dest)
    if numbering != "true":
        key = split.suite.labels
        if key is None or key not in doc:
            raise ScenarioError("<command line>", "--numbering", f"{split.suite.name} has no labels to renumber")
        door_file = dest / doc[key]
        with door_file.open(newline="") as fh:
            rows = list(csv.reader(fh))
        head, body = rows[0], rows[1:]
        k = head.index("number")
        new = relabel([r[k].strip() for r in body], numbering, f"{split.suite.name}/{split.name}/{floor.id}")
        for r in body:
            r[k] = new[r[k].strip()]
        with door_file.open("w", newline="") as fh:
            csv.writer(fh, lineterminator="\n").writerows([head, *body])
        canon = {str(sign_label(a)): b for a, b in new.items()}  # goals as the scenario reads them (a file's "024" is 24)
        doc["goals"] = [sign_label(canon[str(sign_label(g))]) for g in doc["goals"]]
        eps = pd.read_csv(dest / doc["episodes"]["file"], dtype=str, keep_default_na=False)
        eps["goal"] = [str(sign_label(canon[str(sign_label(g))])) for g in eps["goal"]]
        eps["hash"] = [Episode(0, g, float(x), float(y), float(h) if h else None, int(r) if r else None).hash
                       for g, x, y, h, r in zip(eps["goal"], eps["start_x"], eps["start_y"], eps["start_heading"], eps["room"])]
        eps.to_csv(dest / doc["episodes"]["file"], index=False, lineterminator="\n")
    doc["experiment"]["seeds"] = split.suite.repeats
    path = dest / "scenario.yaml"
    atomic_text(path, f"# {split.suite.name} {split.name} floor {floor.id}, numbering {numbering} (semsearch bench)\n"
                + yaml.safe_dump(doc, sort_keys=False))
    return path


def unknown_numbering(numbering: str) -> str:
    """The message for a numbering that is not one of :data:`~.numbering.NUMBERINGS`, with the nearest named."""
    return f"unknown numbering {numbering!r}{did_you_mean(numbering, NUMBERINGS)}; valid: {', '.join(NUMBERINGS)}"


@dataclass
class BenchOutput:
    out: Path
    split: Split
    numbering: str
    runs: pd.DataFrame
    floors: list = field(default_factory=list)  # the floors run (their ids)
    partial: bool = False  # some planner of the folder lacks some run of the split (a --limit run): never official


def _check_bench_file(out: Path, split: Split, numbering: str, planners: list[str]) -> dict:
    """bench.json of ``out`` for this run: a folder of another suite, split, hash or numbering is
    refused; the planners accumulate."""
    f = out / BENCH_FILE
    want = {"suite": split.suite.name, "split": split.name, "hash": split.hash, "numbering": numbering}
    if f.is_file():
        have = read_bench(out)
        for key, value in want.items():
            if have.get(key) != value:
                raise ScenarioError(str(f), key, f"this folder holds {have.get(key)!r}, this run is {value!r}: a bench folder "
                                    "holds one suite, split and numbering; write into another folder with --out")
    else:
        have = dict(want)
    have.pop("runs", None)  # what the folder holds is said when this run ends (an interrupted run claims nothing)
    have["official"] = split.official
    have["repeats"] = split.suite.repeats
    have["kind"] = split.suite.kind
    have["planners"] = list(dict.fromkeys([*have.get("planners", []), *planners]))
    return have


def run_bench(suite: str, planners: list[PlannerSpec], out: str | Path, split: str = "val", numbering: str = "true",
              options: BatchOptions = BatchOptions(), limit: int | None = None, salt_file: str | Path | None = None,
              progress=None) -> BenchOutput:
    """Run ``planners`` on a suite's split into ``out`` (see the module docstring): every floor,
    or the first ``limit`` episodes in the split's order. ``options`` as a batch's (workers,
    executor); decisions are always recorded. ``progress(row, done, total)`` after each run."""
    sp = open_split(suite, split, salt_file)
    if numbering not in NUMBERINGS:
        raise ScenarioError("<command line>", "--numbering", unknown_numbering(numbering))
    if limit is not None and limit < 1:
        raise ScenarioError("<command line>", "--limit", f"{limit}: give at least 1 episode")
    options = options.checked().replace(decisions=True, seeds=None, goals=None, planners=None)
    try:
        variants = expand_variants(planners, "<command line>")
    except ScenarioError:
        variants = []  # a planner the command line names wrong: said of --planner below, with the floor loaded
    preflight(variants, "<command line>", "--planner")  # before the folder, bench.json or a floor is written
    check_bench_out(Path(out))
    out = output_folder(out)
    counts = [len(pd.read_csv(f.scenario.parent / "episodes.csv", usecols=["goal"])) for f in sp.floors]
    todo, left = [], limit
    for f, n in zip(sp.floors, counts):
        if left is not None and left <= 0:
            break
        take = n if left is None else min(n, left)
        todo.append((f, take))
        left = None if left is None else left - take
    with folder_lock(out):
        first = Loaded.load(materialise(sp, todo[0][0], numbering, out / todo[0][0].id / "scenario"))
        try:
            first = first.with_planners(planners)
        except ScenarioError as exc:  # a planner the command line named: said of --planner, not of the floor's copy
            if not exc.field.startswith("planners"):
                raise
            raise ScenarioError("<command line>", "--planner", exc.message) from None
        labels = [v.label for v in first.task.variants()]
        meta = _check_bench_file(out, sp, numbering, labels)
        meta["floors"] = {f.id: {**floor_info(sp, f), "episodes": n} for f, n in zip(sp.floors, counts)}
        meta["limit"] = limit
        meta["partial"] = True  # until every run of the split is in the folder (below)
        atomic_text(out / BENCH_FILE, json.dumps(meta, indent=1) + "\n")
    total = sum(n for _, n in todo) * len(labels) * sp.suite.repeats
    stamp = {"suite": sp.suite.name, "split": sp.name, "suite_hash": sp.hash, "numbering": numbering}
    frames, finished = [], 0  # the runs of this run's specs on the floors before this one
    # one Dask cluster (or client) for every floor; the process pool starts per floor (a fork costs little)
    shared = (make_executor(options.workers, None, options.executor, options.scheduler) if options.executor != "processes"
              else nullcontext())
    with shared as runner:
        for f, take in todo:
            frames.append(_run_floor(sp, f, take, first if f is todo[0][0] else None, planners, numbering, out, options,
                                     {**stamp, "floor": f.id}, runner, progress, total, finished))
            finished += len(frames[-1])
    runs = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    with folder_lock(out):
        meta = json.loads((out / BENCH_FILE).read_text())
        meta["partial"] = bool(missing_runs(out, meta))
        meta["runs"] = floor_runs(out, meta)
        atomic_text(out / BENCH_FILE, json.dumps(meta, indent=1) + "\n")
    return BenchOutput(out, sp, numbering, runs, [f.id for f, _ in todo], meta["partial"])


def floor_runs(out: Path, meta: dict) -> dict[str, int]:
    """Per floor of a bench folder that holds rows, its runs (rows of whole runs): what
    bench.json says the folder holds, which ``verify`` holds the floors to (a floor taken away)."""
    held = {}
    for fid in meta.get("floors", {}):
        f = out / fid / "runs.csv"
        if f.is_file():
            r = read_runs(f)
            held[fid] = int((r["stage"] == "").sum()) if len(r) else 0
    return held


def missing_runs(out: Path, meta: dict) -> dict[str, int]:
    """Per planner of a bench folder (bench.json's ``planners``), the runs of its split it lacks:
    its floors' episodes x the suite's repeats, less the rows it has (a row of a run that failed
    for a cause outside it, ``unavailable:``, is no run). Planners lacking none are left out."""
    want = {fid: int((info or {}).get("episodes", 0)) * int(meta.get("repeats", 1)) for fid, info in meta.get("floors", {}).items()}
    lacking: dict[str, int] = {}
    for lab in meta.get("planners", []):
        have = 0
        for fid in want:
            f = out / fid / "runs.csv"
            if f.is_file():
                r = read_runs(f)
                r = r[(r["stage"] == "") & (r["planner"].astype(str) == lab)]
                r = r[~outside_the_run(r)]
                have += len(r.drop_duplicates(["goal", "episode", "seed"]))
        if have < sum(want.values()):
            lacking[lab] = sum(want.values()) - have
    return lacking


def _run_floor(sp: Split, f: Floor, take: int, loaded, planners, numbering: str, out: Path, options: BatchOptions,
               stamp: dict, runner, progress, total: int, finished: int) -> pd.DataFrame:
    """One floor's batch (its first ``take`` episodes) into ``out/<floor>``; its rows of this run."""
    dest = out / f.id
    if loaded is None:
        loaded = Loaded.load(materialise(sp, f, numbering, dest / "scenario")).with_planners(planners)
    specs = RunList(loaded.task.episodes[:take], loaded.task.variants(), sp.suite.repeats)
    # the planners were looked at once for every floor (run_bench's preflight)
    with Batch(loaded, specs, dest, options, stamp=stamp, own=("decisions_sha256",), looked=True) as batch:
        write_meta(dest, loaded)
        base = finished + sum(1 for k in _keys(batch.done) if specs.has_key(k))  # this floor's runs already there

        def tick(row, n, _total):
            if progress:
                progress(row, base + n, total)

        rows = batch.run(tick, runner=runner)
    own = rows[rows["stage"] == ""] if len(rows) else rows  # (a suite of chains would keep their stage rows too)
    mine = np.array([specs.has_key(k) for k in _keys(own)], bool)  # not the runs a longer run left here
    return own[mine] if len(own) else own


def _keys(rows: pd.DataFrame) -> list[tuple]:
    """The run keys (planner, goal, episode, seed) of a run's own rows (chains' stage rows aside)."""
    if not len(rows):
        return []
    own = rows[rows["stage"] == ""] if "stage" in rows.columns else rows
    return list(zip(own["planner"].astype(str), own["goal"].astype(str), own["episode"].astype(int), own["seed"].astype(int)))


def floor_info(split: Split, floor: Floor) -> dict:
    """What the board shows of a floor without its split at hand (a hidden split, a fetched
    track): its numbering convention (or where it comes from) and its predictability (door
    suites: :mod:`.predictability`, on its true labels)."""
    r = floor.recipe
    conv = r.get("numbering") or {"kth": "KTH floor plan", "mobilesim": "the authors' map"}.get(r.get("importer"), floor.id)
    info = {"convention": conv, "predictability": None}
    key = split.suite.labels
    if key is not None:
        pred = (r.get("predictability") or {}).get("value")
        if pred is None:
            doc = yaml.safe_load(floor.scenario.read_text())
            d = pd.read_csv(floor.scenario.parent / doc[key], dtype={"number": str}, keep_default_na=False)
            pred = predictability(d["number"].tolist(), d["x"], d["y"], d["facing"], floor.id).value
        info["predictability"] = None if pred is None or not np.isfinite(pred) else round(float(pred), 4)
    return info


MAX_BENCH_BYTES = 10_000_000  # a bench.json semsearch writes is kilobytes (one entry per floor)
BENCH_KEYS = ("suite", "split", "hash", "numbering")  # what every bench.json names, as text


def read_bench(folder: Path) -> dict:
    """A bench folder's bench.json, checked: a JSON object naming a known suite, its split, hash
    and numbering (text), and its floors (an object, when given); else a :class:`ScenarioError`
    naming the file."""
    f = Path(folder) / BENCH_FILE
    bad = "not a bench.json semsearch wrote"
    try:
        if f.stat().st_size > MAX_BENCH_BYTES:
            raise ScenarioError(str(f), "", f"{bad} (larger than {MAX_BENCH_BYTES:,} bytes)")
        meta = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise ScenarioError(str(f), "", f"{bad} ({type(exc).__name__}: {str(exc)[:80]})") from None
    if not isinstance(meta, dict):
        raise ScenarioError(str(f), "", f"{bad} (a JSON {type(meta).__name__}, not an object)")
    for key in BENCH_KEYS:
        if not isinstance(meta.get(key), str) or not meta[key]:
            got = "none" if key not in meta else repr(meta[key])[:40]
            raise ScenarioError(str(f), key, f"{bad}: its {key} is {got}, not the text a bench run writes")
    if "floors" in meta and not isinstance(meta["floors"], dict):
        raise ScenarioError(str(f), "floors", f"{bad}: its floors are not an object of floor ids")
    if meta["numbering"] not in NUMBERINGS:
        raise ScenarioError(str(f), "numbering", f"{bad}: {unknown_numbering(meta['numbering'])}")
    try:
        suite = suite_named(meta["suite"])
    except ScenarioError as exc:
        raise ScenarioError(str(f), "suite", exc.message) from None
    if meta["split"] not in suite.splits:
        raise ScenarioError(str(f), "split", f"{bad}: {suite.name} has no split {meta['split']!r}; its splits: "
                            f"{', '.join(suite.splits)}")
    return meta


def is_bench(folder: Path) -> bool:
    return (Path(folder) / BENCH_FILE).is_file()


def check_bench_out(out: Path) -> None:
    """A bench run's ``--out`` is a bench folder or a fresh one: never a plain results folder
    (``semsearch run`` wrote its runs.csv or meta.json there) nor a folder inside a bench folder
    (its floors are its own), for then one folder would mix two kinds of rows and ``verify``
    check one of them. A :class:`ScenarioError` for ``--out``."""
    out = Path(out)
    for p in Path(os.path.abspath(out)).parents:
        if (p / BENCH_FILE).is_file():
            raise ScenarioError("<command line>", "--out", f"{out} lies inside the bench folder {p}: give the bench run a "
                                "folder of its own")
    if (out / BENCH_FILE).exists() and not (out / BENCH_FILE).is_file():
        raise ScenarioError("<command line>", "--out", f"{out / BENCH_FILE} is not a file; give another folder")
    if not is_bench(out):
        plain = [n for n in ("runs.csv", "meta.json") if (out / n).exists()]
        if plain:
            raise ScenarioError("<command line>", "--out", f"{out} is a results folder of `semsearch run` (it holds "
                                f"{plain[0]}): a bench folder and a plain results folder never share a folder; give the "
                                "bench run a folder of its own")


def verify_bench(folder: str | Path, salt_file: str | Path | None = None, workers: int = 1,
                 progress=None) -> tuple[Split, dict[str, Verdict]]:
    """Replay every recorded run of a bench folder from its decisions (no planner built), floor by
    floor, each on its floor rebuilt from the suite (never from the folder's copy): a row made on
    a split of another hash, or that does not replay to its outcome, distance and steps, is
    named. Returns the split and each floor's :class:`~semsearch_cli.runner.verify.Verdict`."""
    folder = Path(folder)
    meta = read_bench(folder)
    check_folder_engine(folder)  # before the split: another engine's runs replay with the release that made them
    sp = open_split(meta["suite"], meta["split"], salt_file)
    if sp.hash != meta.get("hash"):
        raise ScenarioError(str(folder / BENCH_FILE), "hash", f"the results were made on {meta['suite']} {meta['split']} of hash "
                            f"{str(meta.get('hash'))[:16]}, this semsearch's is {sp.hash[:16]}: verify them with the suite they "
                            "were made on")
    verdicts: dict[str, Verdict] = {}
    ids = {f.id for f in sp.floors}
    if (folder / "runs.csv").exists() or (folder / "decisions").exists():  # a plain run's rows, written beside the floors
        verdicts["(top)"] = Verdict(runs=1, failed=[("runs.csv", f"{folder} holds rows of its own beside its floors (a "
                                                     "`semsearch run` into a bench folder): a bench folder's rows are its "
                                                     "floors'")])
    for extra in sorted(p.parent.name for p in folder.glob("*/runs.csv") if p.parent.name not in ids):
        verdicts[extra] = Verdict(runs=1, failed=[("its rows", f"folder {extra} is not a floor of {sp.suite.name} {sp.name}")])
    held = [f.id for f in sp.floors if (folder / f.id / "runs.csv").is_file()]
    order = [f.id for f in sp.floors]
    if held and order[: len(held)] != held:  # a bench run fills the floors in the split's order
        gap = next(fid for fid in order if fid not in held)
        verdicts[gap] = Verdict(runs=1, failed=[("its rows", f"are gone: floor {gap} comes before floors that hold rows "
                                                 f"({held[-1]}), and a bench run fills the floors in order")])
    said = meta.get("runs") if isinstance(meta.get("runs"), dict) else {}
    with tempfile.TemporaryDirectory(prefix="semsearch-verify-") as tmp:
        for f in sp.floors:
            if not (folder / f.id / "runs.csv").is_file():
                if said.get(f.id):
                    verdicts[f.id] = Verdict(runs=int(said[f.id]) if isinstance(said[f.id], int) else 1,
                                             failed=[("its rows", f"are gone: bench.json says floor {f.id} holds "
                                                      f"{said[f.id]} run(s), and it has no runs.csv")])
                continue
            rows = read_runs(folder / f.id / "runs.csv", as_written=True)
            own = rows[rows["stage"] == ""]
            loaded = Loaded.load(materialise(sp, f, meta["numbering"], Path(tmp) / f.id), planners=False)
            try:
                v = verify_folder(folder / f.id, loaded, progress, workers)  # every run recorded: none may lack its record
            except ScenarioError as exc:  # rows of another floor's scenario, none at all: this floor fails, said so
                verdicts[f.id] = Verdict(runs=max(len(own), 1), failed=[("its rows", exc.message)])
                continue
            for col, want, what in (("suite_hash", sp.hash, "another suite hash"), ("floor", f.id, "another floor"),
                                    ("numbering", meta["numbering"], "another numbering than bench.json's")):
                bad = own[col].astype(str) != want if col in own.columns else pd.Series(True, index=own.index)
                if bad.any():
                    v.failed.append((f"{int(bad.sum())} row(s)", f"carry {what} ({col} is not {want[:16]})"))
            if f.id in said and said[f.id] != len(own):
                v.failed.append(("its rows", f"bench.json says floor {f.id} holds {said[f.id]} run(s), its runs.csv holds "
                                 f"{len(own)}"))
            verdicts[f.id] = v
    return sp, verdicts
