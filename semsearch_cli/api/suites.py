"""semsearch-bench's commands: ``bench_run``, ``bench_list``, ``bench_board``, ``bench_fetch`` and
``bench_hash`` (docs/bench.md)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..credentials import redact, url_credential
from ..errors import ScenarioError
from ..runner import BatchOptions
from .. import bench
from .info import planner_spec


def bench_run(suite: str, planners: list[str], out: str | Path, split: str = "val", numbering: str = "true",
              options: BatchOptions = BatchOptions(), limit: int | None = None, salt_file: str | Path | None = None,
              planner_file: str | Path | None = None, progress=None) -> bench.BenchOutput:
    """Run planners (``NAME`` or ``NAME[key=value,...]``, :func:`planner_spec`) on a suite's
    split into ``out`` (:func:`~semsearch_cli.bench.run_bench`)."""
    if not planners:
        raise ScenarioError("<command line>", "--planner", "give the planner to run (NAME or NAME[key=value,...])")
    specs = [planner_spec(p, planner_file) for p in planners]
    return bench.run_bench(suite, specs, out, split, numbering, options, limit, salt_file, progress)


def bench_list() -> list[dict]:
    """Every suite's splits: kind, floors, goals, episodes, repeats, hash (shipped splits) and the
    published hash."""
    rows = []
    for s in bench.SUITES.values():
        for split in s.splits:
            row = {"suite": s.name, "split": split, "kind": s.kind, "repeats": s.repeats, "summary": s.summary,
                   "published": bench.PUBLISHED.get((s.name, split))}
            if split in s.hidden:
                row.update(floors=None, goals=None, episodes=None, hash=None, hidden=True)
            elif s.fetched and not bench.real.is_fetched(s):
                row.update(floors=None, goals=None, episodes=None, hash=None, hidden=False, fetch=True,
                           sources=len(bench.real.read_sources(s.name)["floors"]))
            else:
                sp = bench.open_split(s.name, split)
                eps = [pd.read_csv(f.scenario.parent / "episodes.csv", dtype=str, keep_default_na=False) for f in sp.floors]
                rooms = sum(e["room"].nunique() for e in eps if (e["room"] != "").all())  # indirect search: rooms, not floors
                row.update(floors=f"{rooms} rooms" if rooms else len(sp.floors), goals=sum(e["goal"].nunique() for e in eps),
                           episodes=sum(len(e) for e in eps), hash=sp.hash, hidden=False)
            rows.append(row)
    return rows


def bench_board(folders, out: str | Path) -> list[Path]:
    """The results page of bench folders into ``out`` (index.html, board.md, the figure and the
    per-floor table): :mod:`semsearch_cli.bench.board`."""
    if not folders:
        raise ScenarioError("<command line>", "FOLDERS", "give one or more bench results folders")
    return bench.board.board([Path(f) for f in folders], out)


def bench_fetch(suite: str, from_dirs=(), mirror: str | None = None, partial: bool = False, progress=None):
    """Fetch a track of floors that may not be shipped (:mod:`semsearch_cli.bench.real`) and
    build its split in the cache; returns (the split, the floors left out with why)."""
    s = bench.suite_named(suite)
    if not s.fetched:
        raise ScenarioError("<command line>", "SUITE", f"{suite} is shipped with semsearch: nothing to fetch (the tracks to "
                            f"fetch: {', '.join(n for n, x in bench.SUITES.items() if x.fetched)})")
    for d in from_dirs:
        if not Path(d).is_dir():
            raise ScenarioError(str(d), "--from", "no such folder")
    secret = url_credential(mirror)
    if secret:  # a fetch's messages name the address it fetched
        raise ScenarioError("<command line>", "--mirror", f"{redact(mirror)!r} holds {secret}: a mirror is fetched without "
                            "credentials; serve it where none is needed, or copy the files and give --from DIR")
    return bench.real.fetch(s, [Path(d) for d in from_dirs], mirror, partial, progress)


def bench_hash(suite: str, split: str = "val", salt_file: str | Path | None = None) -> bench.Split:
    """A split, built (a hidden one from ``salt_file``) and hashed: its ``hash`` and whether it is
    the published one (``official``)."""
    return bench.open_split(suite, split, salt_file)
