"""``semsearch bench``: the frozen suites, their runs, board, floors and hashes (docs/bench.md)."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer
from rich.table import Table

from .. import api
from ..runner import BatchOptions
from ..errors import ScenarioError
from .common import EXECUTOR, OVERSUBSCRIBE, SCHEDULER, TRANSCRIPTS, WORKERS, _fail, _fallback_lines, _path, _warn_errors, _with_progress, app, err, out


bench_app = typer.Typer(no_args_is_help=True, help="semsearch-bench: frozen suites, runs that verify by replay (docs/bench.md).")
app.add_typer(bench_app, name="bench")


@bench_app.command("list")
def bench_list():
    """Every suite and split: its kind, floors (or rooms), goals, episodes, repeats and hash."""
    try:
        rows = api.bench_list()
    except ScenarioError as exc:
        _fail(exc)
    t = Table(title="semsearch-bench suites (semsearch bench run SUITE --planner NAME --out DIR)")
    for col in ("suite", "split", "kind", "floors", "goals", "episodes", "repeats", "hash", "published"):
        t.add_column(col, overflow="fold", justify="right" if col in ("floors", "goals", "episodes", "repeats") else "left")
    for r in rows:
        if r.get("fetch"):
            t.add_row(r["suite"], r["split"], r["kind"], f"{r['sources']} to fetch", "", "", str(r["repeats"]),
                      f"(semsearch bench fetch {r['suite']})", str(r["published"] or "")[:16])
        elif r["hidden"]:
            pub = r["published"][:16] if r["published"] else "none yet (a maintainer's)"
            t.add_row(r["suite"], r["split"], r["kind"], "hidden", "", "", str(r["repeats"]), "(salt held by the maintainers)", pub)
        else:
            mark = "= published" if r["hash"] == r["published"] else "DIFFERS from " + str(r["published"])[:16]
            t.add_row(r["suite"], r["split"], r["kind"], str(r["floors"]), str(r["goals"]), str(r["episodes"]), str(r["repeats"]),
                      r["hash"][:16], mark)
    out.print(t)


@bench_app.command("run")
def bench_run(
    suite: str = typer.Argument(..., help="A suite's name (semsearch bench list)."),
    planner: List[str] = typer.Option(..., "--planner", help="NAME or NAME\\[key=value,...], e.g. nsos\\[alpha=0.9] (repeatable)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="The results folder (bench.json, one folder per floor)."),
    split: str = typer.Option("val", "--split", help="val (shipped) or test (hidden: --salt-file)."),
    numbering: str = typer.Option("true", "--numbering", help="true, shuffled, parity-flipped or reversed: the floors' labels permuted."),
    limit: Optional[int] = typer.Option(None, "--limit", min=1, help="Only the first N episodes of the split (a first look)."),
    planner_file: Optional[Path] = typer.Option(None, "--planner-file", help="A Python file that registers the planner(s)."),
    salt_file: Optional[Path] = typer.Option(None, "--salt-file", help="The salt of a hidden split (maintainers)."),
    transcripts: bool = TRANSCRIPTS,
    workers: Optional[int] = WORKERS,
    oversubscribe: bool = OVERSUBSCRIBE,
    executor: str = EXECUTOR,
    scheduler: Optional[str] = SCHEDULER,
):
    """Run planners on a suite's split: every run recorded with its decisions (semsearch verify
    DIR replays them), every row with the suite's hash; resumable."""
    opts = BatchOptions(workers=workers, oversubscribe=oversubscribe, executor=executor, scheduler=scheduler,
                        transcripts=transcripts)
    res = _with_progress(lambda tick: api.bench_run(suite, planner, out_dir, split, numbering, opts, limit, salt_file,
                                                    planner_file, progress=tick))
    runs = res.runs[res.runs["stage"] == ""]
    t = Table(title=f"{res.split.suite.name} {res.split.name}, numbering {res.numbering} ({len(res.floors)} floors; "
                    f"hash {res.split.hash[:16]}{', official' if res.split.official and not res.partial else ''}"
                    f"{'; partial: not every run of the split is in the folder, never official' if res.partial else ''})")
    for col in ("planner", "runs", "success", "SPL", "mean distance m"):
        t.add_column(col, justify="left" if col == "planner" else "right")
    for label, g in runs.groupby("planner", sort=False):
        t.add_row(str(label), str(len(g)), f"{g['success'].mean():.3f}", f"{g['spl'].mean():.3f}", f"{g['distance_m'].mean():.1f}")
    out.print(t)
    _warn_errors(runs)
    out.print(f"results: {res.out} (verify: semsearch verify {res.out})")
    _fallback_lines(runs)


@bench_app.command("board")
def bench_board(
    folders: List[Path] = typer.Argument(..., help="Bench results folders (semsearch bench run --out)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for index.html, board.md and the figure."),
):
    """The results page of bench folders: per suite and split, each planner's success, SPL, SoftSPL
    and distance with 95% intervals over episodes, the paired difference to nsos[alpha=0.9], the
    semantic gain (true minus shuffled numbering), verified or not, official or not."""
    try:
        files = api.bench_board(folders, out_dir)
    except ScenarioError as exc:
        _fail(exc)
    for f in files:
        out.print(f"wrote {f}")


@bench_app.command("fetch")
def bench_fetch(
    suite: str = typer.Argument(..., help="A track of floors that may not be shipped (semsearch bench list)."),
    from_dir: Optional[List[Path]] = typer.Option(None, "--from", help="A folder holding copies of the source files "
                                                  "(found by name and SHA-256; repeatable)."),
    mirror: Optional[str] = typer.Option(None, "--mirror", help="A URL standing for the sources' host (http://HOST:PORT)."),
    partial: bool = typer.Option(False, "--partial", help="Build the split from the floors whose files were found (not official)."),
):
    """Fetch a track's source files (each checked by its SHA-256), import its floors and draw their
    episodes, into the cache: then semsearch bench run SUITE runs it."""
    try:
        sp, missing = api.bench_fetch(suite, from_dir or [], mirror, partial)
    except ScenarioError as exc:
        _fail(exc)
    for m in missing:
        err.print(f"left out: {m}", highlight=False, soft_wrap=True)
    out.print(f"{suite}: {len(sp.floors)} floors in {sp.folder}; hash {sp.hash[:16]} "
              + ("(the published hash: official)" if sp.official else "(not the published hash: not official)"))


@bench_app.command("hash")
def bench_hash(
    suite: str = typer.Argument(..., help="A suite's name (semsearch bench list)."),
    split: str = typer.Option("val", "--split", help="The split."),
    salt_file: Optional[Path] = typer.Option(None, "--salt-file", help="The salt of a hidden split (maintainers)."),
):
    """Print a split's hash (a hidden split built from its salt) and whether it is the published one."""
    try:
        sp = api.bench_hash(suite, split, salt_file)
    except ScenarioError as exc:
        _fail(exc)
    out.print(sp.hash)
    pub = sp.published
    err.print(f"{suite} {split}: {len(sp.floors)} floors; " + ("the published hash" if sp.official else
              "no published hash yet (docs/bench.md: a maintainer fills it in)" if pub is None else
              f"NOT the published hash {pub[:16]}: not official"), highlight=False, soft_wrap=True)
