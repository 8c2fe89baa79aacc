"""A batch: run the specs not yet in ``runs.csv`` on an executor, appending each run's rows as it
finishes, so an interrupted batch keeps every finished run and resumes where it stopped."""

from __future__ import annotations

import os
import sys
from contextlib import ExitStack
from pathlib import Path
from typing import Callable, Sequence

import pandas as pd

from ..engine import ENGINE, release
from ..errors import DISK_FULL, BatchStopped, ScenarioError
from ..files import check_outputs, temp_path
from ..metrics import PRIVILEGED, columns_for, outside_the_run
from ..planners import code_of, planner_class
from ..planners.base import has_preflight, preflight
from .execution import Executor, Watch
from .executors import SerialExecutor, make_executor
from .options import BatchOptions
from .lock import folder_lock
from .specs import Loaded, RunSpec, file_stem
from .store import RowWriter, read_runs, run_rows


BENCH_FILE = "bench.json"  # what marks a bench results folder (semsearch bench run; semsearch_cli.bench)


def check_plain_out(out: Path) -> None:
    """A plain batch's folder (``semsearch run``, a sweep) is never a bench folder nor inside one
    (a floor's): one folder would mix two kinds of rows, and ``verify`` would check one of them.
    A :class:`ScenarioError` for ``--out``."""
    for p in (Path(out), *Path(os.path.abspath(out)).parents):
        if (p / BENCH_FILE).exists():
            where = "is" if p == Path(out) else f"lies inside {p}, which is"
            raise ScenarioError("<command line>", "--out", f"{out} {where} a bench folder (it holds {BENCH_FILE}): a bench "
                                "folder and a plain results folder never share a folder; give the run a folder of its own")


def check_folder(loaded: Loaded, out: Path, force: bool = False, codes: dict | None = None) -> pd.DataFrame:
    """The rows of ``out/runs.csv`` that a batch of ``loaded`` may resume (see :func:`run_batch`);
    a :class:`ScenarioError` when they were made with another scenario, unless ``force``.

    ``codes`` (planner label -> code hash, :func:`~semsearch_cli.planners.code_of`): rows of
    those planners made by other code (an edited planner file, another semsearch) are never
    reused: they are moved to ``runs.superseded.csv`` (appended, so nothing is lost), their runs'
    files (paths, traces, frames, decisions) to ``superseded/<n>/``, said so on standard error, and their runs
    run again; ``force`` keeps another scenario's runs.csv as ``runs.<n>.csv.bak`` and its runs'
    files in ``runs.<n>.bak/``. Before anything: the files and folders a batch and
    its report write are of the kind they will be written as (:func:`~semsearch_cli.files.check_outputs`)."""
    check_outputs(out, BATCH_FILES, BATCH_FOLDERS)
    runs_csv = out / "runs.csv"
    done = run_rows(read_runs(runs_csv, as_written=True))
    fp = loaded.fingerprint
    other = sorted({int(e) for e in done["engine"]} - {ENGINE}) if len(done) else []
    if other and not force:
        raise ScenarioError(str(runs_csv), "engine", f"these rows were made by simulator engine {other[0]} and this semsearch runs "
                            f"engine {ENGINE}, whose runs differ, so they are not resumed or mixed with new ones: write into a "
                            f"fresh folder with --out, add to them with the release that made them ({release(other[0])}), "
                            "or re-run everything here with --force (the old runs.csv is kept as runs.<n>.csv.bak, its runs' "
                            "paths, traces and frames in runs.<n>.bak/)")
    foreign = len(done) and (bool(other) or "fingerprint" not in done.columns or (done["fingerprint"].astype(str) != fp).any())
    if foreign and not force:
        raise ScenarioError(str(runs_csv), "fingerprint", f"these rows were made with another scenario, with {loaded.path} before it was edited, "
                            "or by an older semsearch, so they cannot be resumed; write into a fresh folder with --out, "
                            "or re-run everything here with --force (the old runs.csv is kept as runs.<n>.csv.bak, "
                            "its runs' paths, traces and frames in runs.<n>.bak/)")
    if foreign:  # kept whole: the rows as runs.<n>.csv.bak, their runs' files in runs.<n>.bak/
        n = 1
        while (out / f"runs.{n}.csv.bak").exists() or (out / f"runs.{n}.bak").exists():
            n += 1
        runs_csv.rename(out / f"runs.{n}.csv.bak")
        for d, _ in RUN_FILES:
            if (out / d).is_dir():
                (out / f"runs.{n}.bak").mkdir(exist_ok=True)
                os.replace(out / d, out / f"runs.{n}.bak" / d)
        done = run_rows(read_runs(runs_csv, as_written=True))
    if codes and len(done):
        stale = done["planner"].isin(list(codes)) & (done["code"].astype(str) != done["planner"].map(codes))
        if stale.any():
            names = ", ".join(sorted({str(p) for p in done.loc[stale, "planner"]}))
            _supersede(out, lambda rows: rows["planner"].astype(str).isin(done.loc[stale, "planner"].astype(str)),
                       f"were made by other code ({names}: the planner's file or semsearch changed since)")
            done = run_rows(read_runs(runs_csv, as_written=True))
    if len(done):
        outside = outside_the_run(done)
        if outside.any():  # a cause outside the run (a missing package, a model that did not answer): not done
            keys = set(zip(*(done.loc[outside, c].astype(str) for c in ("planner", "goal", "episode", "seed"))))
            _supersede(out, lambda rows: pd.Series([k in keys for k in zip(*(rows[c].astype(str) for c in ("planner", "goal", "episode", "seed")))],
                                                   index=rows.index, dtype=bool),
                       "failed for a cause outside the run (a package missing, a service that did not answer)")
            done = run_rows(read_runs(runs_csv, as_written=True))
    if len(done):
        moved = _moved_episodes(loaded, done)
        if moved.any():
            keys = set(zip(done.loc[moved, "goal"].astype(str), done.loc[moved, "episode"].astype(int)))
            _supersede(out, lambda rows: pd.Series([k in keys for k in zip(rows["goal"].astype(str), rows["episode"].astype(int))],
                                                   index=rows.index),
                       "belong to episodes whose start is no longer the one at their index (the goals or the "
                       "episode set changed)")
            done = run_rows(read_runs(runs_csv, as_written=True))
    return done


def _moved_episodes(loaded: Loaded, done: pd.DataFrame) -> pd.Series:
    """Rows whose (goal, episode index) no longer names the start they ran from: a row is
    resumed by that index, so a changed episode set must not pass another start's rows off as
    its own."""
    where = {(str(e.goal), e.index): (round(e.x, 4), round(e.y, 4)) for e in loaded.task.episodes}
    got = zip(done["goal"].astype(str), done["episode"].astype(int), done["start_x"].astype(float).round(4),
              done["start_y"].astype(float).round(4))
    return pd.Series([(g, e) in where and where[(g, e)] != (x, y) for g, e, x, y in got], index=done.index)


def _supersede(out: Path, which, why: str) -> None:
    """Move the rows ``which(rows)`` selects (a run's stage rows with it) from runs.csv to the end
    of runs.superseded.csv (nothing is lost), then replace runs.csv atomically; say so on stderr."""
    runs_csv, side = out / "runs.csv", out / "runs.superseded.csv"
    rows = read_runs(runs_csv, as_written=True)  # rewritten as they were written (a goal 4.50 stays 4.50)
    moved = which(rows)
    old = rows[moved]
    header = pd.read_csv(side, nrows=0).columns.tolist() if side.is_file() and side.stat().st_size else None
    with open(side, "a", encoding="utf-8", newline="") as fh:
        (old if header is None else old.reindex(columns=header)).to_csv(fh, index=False, header=header is None)
        fh.flush()
        os.fsync(fh.fileno())
    tmp = temp_path(runs_csv)
    with open(tmp, "w", encoding="utf-8", newline="") as fh:
        rows[~moved].to_csv(fh, index=False)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, runs_csv)
    stems = {file_stem(str(p), g, int(s), int(e)) for p, g, s, e in zip(old["planner"], old["goal"], old["seed"], old["episode"])}
    files = [out / d / f"{st}{ext}" for st in sorted(stems) for d, ext in RUN_FILES if (out / d / f"{st}{ext}").is_file()]
    where = ""
    if files:
        aside = _next_free(out / "superseded")
        for f in files:
            (aside / f.parent.name).mkdir(parents=True, exist_ok=True)
            os.replace(f, aside / f.parent.name / f.name)
        kinds = ", ".join(d for d, _ in RUN_FILES if any(f.parent.name == d for f in files))
        where = f", and their {len(files)} file(s) ({kinds}) to {aside.relative_to(out)}/"
    print(f"{int(moved.sum())} row(s) in {runs_csv} {why}: moved to {side.name}{where}; their runs run again", file=sys.stderr)


RUN_FILES = (("paths", ".npz"), ("traces", ".jsonl"), ("frames", ".npz"), ("decisions", ".json"))  # a run's files, by its stem


def _next_free(folder: Path) -> Path:
    """``folder/<n>`` for the first n = 1, 2, ... that does not exist."""
    n = 1
    while (folder / str(n)).exists():
        n += 1
    return folder / str(n)


# what a batch, and the report that follows it, write into a results folder
BATCH_FILES = ("runs.csv", "runs.superseded.csv", "meta.json", "summary.csv", "report.md", "report.html")
BATCH_FOLDERS = ("paths", "traces", "frames", "decisions", "superseded", "tables", "figures", "logs")
MANY_RUNS = 10_000  # a batch this large says how many runs it has before it starts
LARGE_RUN = 1e9  # bytes: a batch whose runs need more than this each says so before it starts


def available_memory() -> int | None:
    """Bytes of memory the machine has available now (Linux: MemAvailable), or None."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def check_memory(loaded: Loaded, workers: int) -> None:
    """Before a batch starts: the memory a run needs, times the workers, against what the machine
    has available; refused (a :class:`ScenarioError` for ``--workers``) with the number of
    workers that would fit, and said on stderr when a run needs more than 1 GB."""
    need = loaded.task.memory_per_run()
    have = available_memory()
    if have is not None and need * workers > have:
        fit = have // max(need, 1)
        hint = (f"run with --workers {fit}" if fit >= 1 else "a run alone does not fit: take a coarser map resolution or "
                "a smaller map")
        raise ScenarioError("<command line>", "--workers", f"each run needs about {need / 1e9:.1f} GB, so {workers} "
                            f"workers need {need * workers / 1e9:.1f} GB, and this machine has {have / 1e9:.1f} GB "
                            f"available; {hint}")
    if need > LARGE_RUN:
        print(f"note: each run needs about {need / 1e9:.1f} GB of memory ({workers} worker(s)); a run on a map this large "
              "prints its progress every few seconds", file=sys.stderr)


class Batch:
    """One batch into one folder, held and checked once for the whole command: entering takes the
    folder's lock (:func:`folder_lock`) and checks its rows (:func:`check_folder`, with each
    variant's code hash, so rows of a changed planner are set aside); :meth:`run` then runs the
    specs not yet done. A command that writes more into the folder (meta.json, the logs a scenario
    records) does so inside the ``with``, after the check::

        with Batch(loaded, specs, out, options) as batch:
            write_meta(out, loaded)
            rows = batch.run(progress)

    ``stamp``: columns written with the same value on every row (a bench run's suite, split,
    hash, numbering and floor: :data:`~semsearch_cli.metrics.BENCH_COLUMNS`); ``own``: columns
    each run's rows bring themselves, written in this folder (a bench run's ``decisions_sha256``).
    Entering it looks at the planners with runs left (:meth:`~semsearch_cli.planners.Planner.preflight`)
    before the folder is touched, unless ``looked`` (the caller did, once for several batches).
    """

    def __init__(self, loaded: Loaded, specs: Sequence[RunSpec], out: Path, options: BatchOptions = BatchOptions(),
                 stamp: dict | None = None, own: tuple = (), looked: bool = False):
        self.loaded, self.specs, self.out, self.options = loaded, specs, Path(out), options
        self.looked = looked  # the caller looked at the planners already (Planner.preflight): not again
        self.stamp, self.own = dict(stamp or {}), tuple(own)
        self.variants = specs.variants if hasattr(specs, "variants") else list(dict.fromkeys(s.variant for s in specs))
        self.codes = {v.label: code_of(v)["hash"] for v in self.variants}
        self.done: pd.DataFrame | None = None
        self._stack: ExitStack | None = None

    def __enter__(self) -> "Batch":
        # a planner that cannot run at all (a language model's endpoint that does not answer, a
        # package it needs): refused before the folder is made, locked or touched
        if not self.stamp:  # a bench run's floors carry its stamp; any other batch is a plain one
            check_plain_out(self.out)
        if not self.looked:
            preflight(_pending(self.variants, self.specs, _have(self.out / "runs.csv")), str(self.loaded.path))
        with ExitStack() as stack:
            stack.enter_context(folder_lock(self.out))
            self.done = check_folder(self.loaded, self.out, self.options.force, self.codes)
            self._stack = stack.pop_all()
        return self

    def __exit__(self, *exc) -> None:
        stack, self._stack = self._stack, None
        if stack is not None:
            stack.close()

    def run(self, progress: Callable[[dict, int, int], None] | None = None, runner: Executor | None = None) -> pd.DataFrame:
        """Run the specs not yet in runs.csv (see :func:`run_batch`); returns every row of the
        file afterwards."""
        if self._stack is None:
            raise RuntimeError("run a Batch inside its with block (the folder held and checked)")
        loaded, specs, out, options, done = self.loaded, self.specs, self.out, self.options, self.done
        runs_csv = out / "runs.csv"
        workers, executor = options.workers or 1, options.executor
        watch = Watch(options.trace, options.frames, options.decisions, options.transcripts)
        fp = loaded.fingerprint
        codes = self.codes
        have = {(str(p), str(g), int(e), int(s)) for p, g, e, s in zip(done["planner"], done["goal"], done["episode"], done["seed"])} \
            if len(done) else set()
        has = getattr(specs, "has_key", None) or {s.key for s in specs}.__contains__
        total = len(specs) - sum(1 for k in have if has(k))
        todo = (s for s in specs if s.key not in have)
        if total >= MANY_RUNS:
            print(f"runs: {total:,} to do ({len(self.variants):,} planner variant(s) x goals, episodes and seeds)", file=sys.stderr)
        if total and executor == "processes" and runner is None:
            check_memory(loaded, max(1, min(workers, total)))
        if runner is None:
            serial = total == 0 or (executor == "processes" and total == 1)
            runner = SerialExecutor() if serial else make_executor(max(1, min(workers, total)), options.start_method, executor,
                                                                   options.scheduler)
        # a language model's calls and tokens: the columns of every planner of the scenario, so that a
        # folder first run with another planner alone (--planner) still has them
        costs = [c for v in [*self.variants, *loaded.task.variants()] for c in planner_class(v).cost_columns]
        # what a privileged planner was told, on each of its rows (a reference, never a competitor)
        told = {v.label: planner_class(v).privileged for v in self.variants}
        marks = [PRIVILEGED] if any(told.values()) else []
        writer = RowWriter(runs_csv, columns_for([*loaded.task.columns, *costs, *marks, *self.stamp, *self.own]))
        n = 0
        try:
            for rows in runner.rows(loaded, todo, out, watch):
                for r in rows:
                    r["fingerprint"] = fp
                    r["code"] = codes.get(r["planner"], "")
                    r["engine"] = ENGINE
                    r[PRIVILEGED] = told.get(r["planner"], "")
                    r.update(self.stamp)
                writer.write(rows)
                n += 1
                if progress:
                    progress(rows[0], n, total)
        except OSError as exc:
            if exc.errno in DISK_FULL:
                raise BatchStopped(f"the disk is full ({exc.filename or runs_csv}); free some space") from None
            raise
        finally:
            try:
                writer.close()
            except OSError:
                pass
        return read_runs(runs_csv)


def _have(runs_csv: Path) -> set:
    """The (planner, goal, episode, seed) keys of runs.csv's runs that are done, read without the
    folder's lock and changing nothing (a run that could not run, ``unavailable:``, is not done;
    a file that is not a runs.csv: none, and :func:`check_folder` says why)."""
    try:
        done = run_rows(read_runs(runs_csv, as_written=True))
    except ScenarioError:
        return set()
    if not len(done):
        return set()
    done = done[~outside_the_run(done)]
    return {(str(p), str(g), int(e), int(s)) for p, g, e, s in zip(done["planner"], done["goal"], done["episode"], done["seed"])}


def _pending(variants, specs, have: set) -> list:
    """The variants whose planner looks before it runs (:meth:`~semsearch_cli.planners.Planner.preflight`)
    with a run left to do (a spec whose key is not in ``have``); a pass over the specs that stops
    once every such variant is found (none: no pass)."""
    left, found = {v for v in variants if has_preflight(planner_class(v))}, []
    if not left:
        return found
    for s in specs:
        if s.variant in left and s.key not in have:
            left.discard(s.variant)
            found.append(s.variant)
            if not left:
                break
    return found


def run_batch(loaded: Loaded, specs: Sequence[RunSpec], out: Path, options: BatchOptions = BatchOptions(),
              progress: Callable[[dict, int, int], None] | None = None, runner: Executor | None = None) -> pd.DataFrame:
    """Run the specs not yet in ``out/runs.csv``; returns all rows of the file afterwards.

    Of the :class:`BatchOptions`, ``workers`` (None: one), ``executor``, ``scheduler`` and
    ``start_method`` say where the runs run (see :func:`make_executor`: rows do not depend on it,
    and a batch started on one resumes on another); ``trace`` writes each run's decision trace to
    ``out/traces/``, ``frames`` its replay's frames to ``out/frames/``, ``decisions`` its decisions
    (the choices that replay it, ``semsearch verify``) to ``out/decisions/``; ``force`` is below.
    ``runner``, an executor the caller made (and entered), e.g. one Dask cluster for every value of
    a sweep, replaces the executor options. ``progress(row, done, total)`` is called as each run
    finishes, with the runs finished so far and the runs this batch has to do. The specs are
    streamed to the executor, never listed whole (a :class:`~semsearch_cli.runner.specs.RunList`
    of any length costs no memory).

    The folder is locked for the batch (see :func:`folder_lock`). Rows carry the scenario's
    fingerprint (:attr:`Loaded.fingerprint`); rows of another scenario (or an edited one) in the
    folder are refused, unless ``force``, which moves that runs.csv aside (kept as
    ``runs.<n>.csv.bak``) and starts afresh."""
    with Batch(loaded, specs, out, options) as batch:
        return batch.run(progress, runner)
