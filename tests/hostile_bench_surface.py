"""Hostile inputs for ``semsearch verify``, ``semsearch bench board`` and ``semsearch bench``
(issue 52, items 2 and 3), in the style of ``tests/hostile_release.py``: one class per surface,
each case a command and what must happen.

Classes: ``verify`` (a results folder recorded with ``run --decisions``, and a bench folder,
falsified on disk: a record deleted, replaced by a folder, of another run, not JSON; a row added,
duplicated, edited, cut short; a floor taken away or added; bench.json damaged), ``board`` (the
same runs twice, malformed bench.json and verify.json, missing columns, folders that are no bench
folder) and ``bench`` (``bench run``, ``hash`` and ``list`` inputs: an unknown suite, a bad
``--limit`` or ``--numbering``, ``--out`` colliding with a plain or another bench folder, a salt
file that is a FIFO, a folder or huge).

Each case is a :class:`~tests.hostile_release.ReleaseCase`: ``refuse`` (exit 2, no traceback, the
output holds each of ``says``), ``accept`` (exit 0) or ``fail`` (exit 1 with ``says`` in the
output: a verify that finds the folder falsified). :func:`build_cases` makes one real results
folder (two greedy runs on the demo building, recorded with their decisions, ~2 s) and one real
bench folder (``bench run doors-v1 --limit 2``, ~2 s), and copies them for each case that changes
them, so cases may run in any order.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pandas as pd
import yaml
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.runner import BatchOptions

from .hostile_inputs import _dump, _set, demo_base
from .hostile_release import ReleaseCase

CLASSES = ("verify", "board", "bench")
RUN0 = "greedy__goal304__ep0__seed0.json"  # the first run's record (goal 304, episode 0, repeat 0)
RUN1 = "greedy__goal452__ep1__seed0.json"  # the second run's


def make_results(root: Path) -> tuple[Path, Path]:
    """A real results folder (greedy on the demo building, goals 304 and 452, one repeat each,
    decisions recorded) and its scenario; made once under ``root``."""
    base, _ = demo_base(root)
    scenario = _dump(root / "recorded.yaml", _set(base, ["goals"], [304, 452]))
    out = root / "recorded"
    if not (out / "runs.csv").is_file():
        api.run(scenario, BatchOptions(workers=1, decisions=True, out=str(out)), plots=False)
    if len(list((out / "decisions").glob("*.json"))) != 2:
        raise RuntimeError(f"the recorded results folder {out} holds no two records")
    return out, scenario


def make_bench(root: Path) -> Path:
    """A real bench folder (doors-v1 val, greedy, its first 2 episodes); made once under ``root``."""
    out = root / "bench"
    if not (out / "bench.json").is_file():
        res = CliRunner().invoke(app, ["bench", "run", "doors-v1", "--planner", "greedy", "--limit", "2", "--workers", "1",
                                       "--out", str(out)])
        if res.exit_code != 0:
            raise RuntimeError(f"the bench folder could not be made: {res.output}")
    return out


def _rows(folder: Path, floor: str = "") -> Path:
    return folder / floor / "runs.csv" if floor else folder / "runs.csv"


def _edit_rows(f: Path, edit) -> None:
    """runs.csv ``f`` read as text, changed by ``edit(rows) -> rows``, written back."""
    rows = pd.read_csv(f, dtype=str, keep_default_na=False)
    edit(rows).to_csv(f, index=False)


def _set_cell(f: Path, col: str, value: str, row: int = 0) -> None:
    def edit(r):
        r.loc[row, col] = value
        return r
    _edit_rows(f, edit)


def _record(folder: Path, name: str, edit, keep_digest: bool = True) -> None:
    """decisions/``name`` changed by ``edit(record) -> record``, and the row's decisions_sha256
    changed to match when ``keep_digest`` (so the check that remains is the replay's)."""
    import hashlib
    f = folder / "decisions" / name
    f.write_text(json.dumps(edit(json.loads(f.read_text())), separators=(",", ":")) + "\n")
    if keep_digest:
        digest = hashlib.sha256(f.read_bytes()).hexdigest()
        stem = name[: -len(".json")]

        def match(r):
            stems = r["planner"] + "__goal" + r["goal"] + "__ep" + r["episode"] + "__seed" + r["seed"]
            r.loc[stems == stem, "decisions_sha256"] = digest
            return r
        _edit_rows(folder / "runs.csv", match)


def _blank_digests(folder: Path) -> None:
    def edit(r):
        r["decisions_sha256"] = ""
        return r
    _edit_rows(folder / "runs.csv", edit)


def build_cases(root: Path) -> list[ReleaseCase]:
    """Every case, its files under ``root`` (one results folder and one bench folder made by real
    runs, then a copy of either per case that changes it)."""
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    results, scenario = make_results(root)
    bench = make_bench(root)
    cases: list[ReleaseCase] = []
    sc = ["--scenario", str(scenario)]  # a copied folder: its meta.json names the scenario relative to the original
    w1 = ["--workers", "1"]

    def add(category, name, args, expect="refuse", says=(), fast=True, within=None):
        assert category in CLASSES, category
        cases.append(ReleaseCase(category, name, [str(a) for a in args], expect, False, tuple(says), fast=fast, within=within))

    def copy(of: Path, name: str) -> Path:
        d = root / "cases" / f"{len(cases):03d}-{name}"
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(of, d, symlinks=True)
        return d

    def out_dir() -> Path:
        return root / "out" / f"case{len(cases):03d}"

    def verify(name, change=None, expect="fail", says=(), extra=()):
        d = copy(results, "verify")
        if change is not None:
            change(d)
        add("verify", name, ["verify", d, *sc, *w1, *extra], expect, says)

    # -- verify: a results folder recorded with run --decisions ------------------------------------
    verify("the folder as recorded", expect="accept", says=["2 of 2 runs replayed"])
    verify("the folder as recorded, --allow-unrecorded", expect="accept", extra=["--allow-unrecorded"], says=["2 of 2"])
    verify("a record deleted", lambda d: (d / "decisions" / RUN0).unlink(),
           says=["greedy goal 304 episode 0 seed 0", "is gone", "1 of 2 runs"])
    verify("a record deleted, --allow-unrecorded (its row names it)", lambda d: (d / "decisions" / RUN0).unlink(),
           says=["which the row names", "is gone"], extra=["--allow-unrecorded"])
    verify("a record deleted and its row's digest blanked", lambda d: ((d / "decisions" / RUN0).unlink(), _blank_digests(d)),
           says=["greedy goal 304 episode 0 seed 0: has no decisions record", "--allow-unrecorded"])
    verify("a record deleted and its digest blanked, --allow-unrecorded",
           lambda d: ((d / "decisions" / RUN0).unlink(), _blank_digests(d)), expect="accept",
           says=["1 without decisions not checked"], extra=["--allow-unrecorded"])
    verify("a record replaced by a folder", lambda d: ((d / "decisions" / RUN0).unlink(), (d / "decisions" / RUN0).mkdir()),
           says=["is not a file"])
    verify("a record replaced by a symlink to a folder",
           lambda d: ((d / "decisions" / RUN0).unlink(), (d / "decisions" / RUN0).symlink_to(d)), says=["is not a file"])
    verify("every record deleted (decisions/ gone)", lambda d: shutil.rmtree(d / "decisions"), says=["is gone", "0 of 2"])
    verify("decisions/ gone and the digests blanked", lambda d: (shutil.rmtree(d / "decisions"), _blank_digests(d)),
           expect="refuse", says=["decisions", "has a decisions record"])
    verify("decisions is a file", lambda d: (shutil.rmtree(d / "decisions"), (d / "decisions").write_text("x")),
           says=["is gone"])
    verify("a row's seed edited 0 -> 5", lambda d: _set_cell(_rows(d), "seed", "5"),
           says=["seed 5", "decisions/" + RUN0, "a record without its row"])
    verify("a row's seed edited to -1", lambda d: _set_cell(_rows(d), "seed", "-1"), expect="refuse", says=["runs.csv", "seed"])
    verify("a row's seed edited to 1.5", lambda d: _set_cell(_rows(d), "seed", "1.5"), says=["not whole numbers"])
    verify("a row's seed edited to 1e12", lambda d: _set_cell(_rows(d), "seed", "1000000000000"), says=["not whole numbers"])
    verify("a row's episode edited to 7 (no such episode)", lambda d: _set_cell(_rows(d), "episode", "7"),
           says=["no episode 7 of goal 304"])
    verify("a row's goal edited to 999", lambda d: _set_cell(_rows(d), "goal", "999"), says=["no episode 0 of goal 999"])
    verify("a row's start edited", lambda d: _set_cell(_rows(d), "start_x", "3.0"), says=["starts at"])
    verify("a row's planner renamed", lambda d: _set_cell(_rows(d), "planner", "bvp"),
           says=["bvp goal 304 episode 0 seed 0", "a record without its row"])

    def added(d, seed="2"):
        def edit(r):
            x = r.iloc[[0]].copy()
            x["seed"] = seed
            return pd.concat([r, x], ignore_index=True)
        _edit_rows(_rows(d), edit)
    verify("a row added (a repeat never run)", added, says=["greedy goal 304 episode 0 seed 2", "2 of 3"])
    verify("a row added, --allow-unrecorded (it names a record that is not there)", added, says=["seed 2", "is gone"],
           extra=["--allow-unrecorded"])
    verify("a row duplicated", lambda d: _edit_rows(_rows(d), lambda r: pd.concat([r, r.iloc[[0]]], ignore_index=True)),
           says=["appears 2 times"])
    verify("every row duplicated", lambda d: _edit_rows(_rows(d), lambda r: pd.concat([r, r], ignore_index=True)),
           says=["appears 2 times", "0 of 4"])
    verify("a row deleted (its record left)", lambda d: _edit_rows(_rows(d), lambda r: r.iloc[1:]),
           says=["decisions/" + RUN0, "a record without its row"])
    verify("a row edited to 5.0 m with its record deleted",
           lambda d: (_set_cell(_rows(d), "distance_m", "5.0"), (d / "decisions" / RUN0).unlink()), says=["is gone"])
    verify("a row edited to 5.0 m, record deleted, digest blanked, --allow-unrecorded",
           lambda d: (_set_cell(_rows(d), "distance_m", "5.0"), (d / "decisions" / RUN0).unlink(), _blank_digests(d)),
           says=["below its episode's shortest path"], extra=["--allow-unrecorded"])
    verify("a row's distance edited (record kept)", lambda d: _set_cell(_rows(d), "distance_m", "12.0"),
           says=["distance_m: 12.0 recorded"])
    verify("a row's steps edited", lambda d: _set_cell(_rows(d), "steps", "3"), says=["steps: 3 recorded"])
    verify("a row's outcome edited", lambda d: _set_cell(_rows(d), "outcome", "budget"), says=["outcome: budget recorded"])
    verify("a row made an error that claims success (record deleted, digest blanked)",
           lambda d: (_set_cell(_rows(d), "outcome", "error"), (d / "decisions" / RUN0).unlink(), _blank_digests(d)),
           says=["claims a result"])

    def as_error(d):
        def edit(r):
            r.loc[0, ["outcome", "success", "distance_m", "decisions_sha256"]] = ["error", "0", "", ""]
            return r
        _edit_rows(_rows(d), edit)
        (d / "decisions" / RUN0).unlink()
    verify("a run turned into an error row that claims nothing", as_error, expect="accept",
           says=["1 error or timeout run(s) not replayed"])
    verify("runs.csv cut in the middle of its last row",
           lambda d: _rows(d).write_bytes(_rows(d).read_bytes()[:-40]), says=["a record without its row"])
    verify("runs.csv cut to its header", lambda d: _rows(d).write_text(_rows(d).read_text().splitlines()[0] + "\n"),
           expect="refuse", says=["runs.csv", "holds no rows"])
    verify("runs.csv empty", lambda d: _rows(d).write_text(""), expect="refuse", says=["holds no rows"])
    verify("runs.csv deleted", lambda d: _rows(d).unlink(), expect="refuse", says=["no runs.csv"])
    verify("runs.csv of binary garbage", lambda d: _rows(d).write_bytes(bytes(range(256)) * 4), expect="refuse",
           says=["runs.csv"])
    verify("runs.csv a folder", lambda d: (_rows(d).unlink(), _rows(d).mkdir()), expect="refuse", says=["runs.csv"])
    verify("a record of the other run in its place",
           lambda d: shutil.copyfile(d / "decisions" / RUN1, d / "decisions" / RUN0), says=["is not the record the row names"])
    verify("a record of the other run in its place, digests blanked",
           lambda d: (shutil.copyfile(d / "decisions" / RUN1, d / "decisions" / RUN0), _blank_digests(d)),
           says=["records another run (greedy goal 452 episode 1 seed 0)"])
    verify("a row's digest edited", lambda d: _set_cell(_rows(d), "decisions_sha256", "0" * 64),
           says=["SHA-256 differs"])
    verify("a record that is not JSON", lambda d: (d / "decisions" / RUN0).write_text("{not json"),
           says=["SHA-256 differs"])
    verify("a record that is not JSON, digests blanked",
           lambda d: ((d / "decisions" / RUN0).write_text("{not json"), _blank_digests(d)),
           says=["not a decisions file semsearch wrote"])
    verify("a record that is a JSON list, digests blanked",
           lambda d: ((d / "decisions" / RUN0).write_text("[1, 2]"), _blank_digests(d)), says=["not a decisions file"])
    verify("a record added (of no row)", lambda d: shutil.copyfile(d / "decisions" / RUN0,
                                                                 d / "decisions" / "greedy__goal304__ep0__seed9.json"),
           says=["greedy__goal304__ep0__seed9.json", "a record without its row"])
    verify("a stray file in decisions/", lambda d: (d / "decisions" / "notes.txt").write_text("x"),
           says=["notes.txt", "not a record semsearch writes"])
    verify("a record's decisions cut short (digest matched)",
           lambda d: _record(d, RUN0, lambda r: {**r, "decisions": r["decisions"][:1]}),
           says=["greedy goal 304 episode 0 seed 0"])
    verify("a record's fingerprint edited (digest matched)", lambda d: _record(d, RUN0, lambda r: {**r, "fingerprint": "0" * 16}),
           says=["recorded on another scenario"])
    verify("a record's seed edited (digest matched)", lambda d: _record(d, RUN0, lambda r: {**r, "seed": 1}),
           says=["records another run"])
    verify("a row's fingerprint edited", lambda d: _set_cell(_rows(d), "fingerprint", "0" * 16), expect="refuse",
           says=["fingerprint", "another scenario"])
    other = _dump(root / "other.yaml", _set(demo_base(root)[0], ["goals"], [304]))
    d = copy(results, "verify")
    add("verify", "--scenario of the same building with one goal fewer", ["verify", d, "--scenario", other, *w1], "fail",
        says=["no episode 1 of goal 452"])
    moved = _dump(root / "moved.yaml", _set(_set(demo_base(root)[0], ["goals"], [304, 452]), ["experiment", "max_distance"], 200.0))
    add("verify", "--scenario of another scenario (another budget)", ["verify", copy(results, "verify"), "--scenario", moved, *w1],
        says=["fingerprint", "another scenario"])
    add("verify", "--salt-file on a plain folder", ["verify", copy(results, "verify"), *sc, "--salt-file", other],
        says=["--salt-file", "not a bench folder"])
    add("verify", "--workers 999", ["verify", copy(results, "verify"), *sc, "--workers", "999"], says=["--workers"])
    add("verify", "--workers 0", ["verify", copy(results, "verify"), *sc, "--workers", "0"], says=["--workers"])
    (root / "empty").mkdir(exist_ok=True)
    add("verify", "an empty folder", ["verify", root / "empty", *w1], says=["no runs.csv"])
    add("verify", "a folder that does not exist", ["verify", root / "nowhere", *w1], says=["no runs.csv"])

    # -- verify: a bench folder ---------------------------------------------------------------------
    def bverify(name, change=None, expect="fail", says=(), extra=()):
        d = copy(bench, "bverify")
        if change is not None:
            change(d)
        add("verify", f"bench: {name}", ["verify", d, *w1, *extra], expect, says)

    def bench_json(edit):
        def change(d):
            f = d / "bench.json"
            meta = json.loads(f.read_text())
            out = edit(meta)
            f.write_text(out if isinstance(out, str) else json.dumps(out))
        return change

    def without(key):
        return bench_json(lambda m: {k: v for k, v in m.items() if k != key})

    f0 = "f000"
    bverify("the folder as run", expect="accept", says=["2 of 2 runs replayed", "doors-v1 val"])
    bverify("its floor folder removed", lambda d: shutil.rmtree(d / f0), says=["floor f000", "are gone"])
    bverify("its floor folder removed and bench.json's runs with it",
            lambda d: (shutil.rmtree(d / f0), bench_json(lambda m: {k: v for k, v in m.items() if k != "runs"})(d)),
            expect="refuse", says=["holds no floor with rows"])
    bverify("a floor folder added (no floor of the split)", lambda d: shutil.copytree(d / f0, d / "f999"),
            says=["folder f999 is not a floor of doors-v1 val"])
    bverify("a floor after a missing one", lambda d: (shutil.copytree(d / f0, d / "f002"), shutil.rmtree(d / f0),
                                                    bench_json(lambda m: {k: v for k, v in m.items() if k != "runs"})(d)),
            says=["floor f000", "are gone", "floor f002: its rows", "fingerprint"])
    bverify("bench.json without its split", without("split"), expect="refuse", says=["bench.json", "split"])
    bverify("bench.json without its hash", without("hash"), expect="refuse", says=["bench.json", "hash"])
    bverify("bench.json without its suite", without("suite"), expect="refuse", says=["bench.json", "suite"])
    bverify("bench.json without its numbering", without("numbering"), expect="refuse", says=["bench.json", "numbering"])
    bverify("bench.json of another suite hash", bench_json(lambda m: {**m, "hash": "0" * 64}), expect="refuse",
            says=["bench.json", "hash"])
    bverify("bench.json of an unknown suite", bench_json(lambda m: {**m, "suite": "doors-v9"}), expect="refuse",
            says=["bench.json", "doors-v9"])
    bverify("bench.json of an unknown split", bench_json(lambda m: {**m, "split": "train"}), expect="refuse",
            says=["bench.json", "train"])
    bverify("bench.json of a numbering that is none", bench_json(lambda m: {**m, "numbering": "sideways"}), expect="refuse",
            says=["bench.json", "sideways"])
    bverify("bench.json's split a number", bench_json(lambda m: {**m, "split": 3}), expect="refuse", says=["bench.json", "split"])
    bverify("bench.json not JSON", bench_json(lambda m: "{not json"), expect="refuse", says=["bench.json", "not a bench.json"])
    bverify("bench.json a JSON list", bench_json(lambda m: "[1, 2]"), expect="refuse", says=["bench.json", "list"])
    bverify("bench.json a JSON string", bench_json(lambda m: '"doors-v1"'), expect="refuse", says=["bench.json", "str"])
    bverify("bench.json empty", bench_json(lambda m: ""), expect="refuse", says=["bench.json"])
    bverify("bench.json a folder", lambda d: ((d / "bench.json").unlink(), (d / "bench.json").mkdir()), expect="refuse",
            says=["no runs.csv"])
    bverify("bench.json says the floor holds 3 runs", bench_json(lambda m: {**m, "runs": {"f000": 3}}),
            says=["bench.json says floor f000 holds 3 run(s)"])
    bverify("a record deleted", lambda d: next((d / f0 / "decisions").glob("*.json")).unlink(), says=["floor f000", "is gone"])
    bverify("a row added", lambda d: added(d / f0, "1"), says=["floor f000", "seed 1"])
    bverify("a row duplicated", lambda d: _edit_rows(_rows(d, f0), lambda r: pd.concat([r, r.iloc[[0]]], ignore_index=True)),
            says=["appears 2 times"])
    bverify("a row naming another floor", lambda d: _set_cell(_rows(d, f0), "floor", "f001"), says=["another floor"])
    bverify("a row of another numbering", lambda d: _set_cell(_rows(d, f0), "numbering", "shuffled"),
            says=["another numbering"])
    bverify("a row's distance edited", lambda d: _set_cell(_rows(d, f0), "distance_m", "1.0"), says=["distance_m: 1.0 recorded"])
    bverify("a plain runs.csv at the top of the folder", lambda d: shutil.copyfile(_rows(results), d / "runs.csv"),
            says=["holds rows of its own beside its floors"])
    add("verify", "bench: --scenario given", ["verify", copy(bench, "bverify"), "--scenario", scenario, *w1], says=["--scenario"])
    add("verify", "bench: --allow-unrecorded", ["verify", copy(bench, "bverify"), "--allow-unrecorded", *w1],
        says=["--allow-unrecorded"])
    add("verify", "bench: --salt-file of a public split", ["verify", copy(bench, "bverify"), "--salt-file", other, *w1],
        says=["--salt-file"])

    # -- board --------------------------------------------------------------------------------------
    def board(name, folders, expect="refuse", says=()):
        add("board", name, ["bench", "board", *folders, "--out", out_dir()], expect, says)

    b = copy(bench, "board")
    board("one bench folder", [b], "accept", says=["board.md"])
    board("the same folder twice", [b, b], says=[str(b), "given again"])
    c = copy(bench, "board")
    board("a folder and its copy", [b, c], says=[str(b), str(c), "counts each run once"])
    link = root / "cases" / f"{len(cases):03d}-link"
    if not link.is_symlink():
        link.symlink_to(b)
    board("a folder and a symlink to it", [b, link], says=[str(b), "given again"])
    board("a folder and itself as b/.", [b, b / "."], says=["given again"])

    def bboard(name, change, expect="refuse", says=()):
        d = copy(bench, "board")
        change(d)
        board(name, [d], expect, says)

    bboard("bench.json without its hash", without("hash"), says=["bench.json", "hash"])
    bboard("bench.json without its numbering", without("numbering"), says=["bench.json", "numbering"])
    bboard("bench.json not JSON", bench_json(lambda m: "{not json"), says=["bench.json", "not a bench.json"])
    bboard("bench.json a JSON list", bench_json(lambda m: "[]"), says=["bench.json", "list"])
    bboard("bench.json a JSON number", bench_json(lambda m: "7"), says=["bench.json", "int"])
    bboard("bench.json's floors a list", bench_json(lambda m: {**m, "floors": ["f000"]}), says=["bench.json", "floors"])
    bboard("bench.json without floors", without("floors"), says=["bench.json", "floors"])
    bboard("bench.json of over 10 MB", bench_json(lambda m: json.dumps({**m, "pad": "x" * 10_000_001})),
           says=["bench.json", "larger than"])
    bboard("verify.json a JSON list", lambda d: (d / "verify.json").write_text("[1]"), says=["verify.json"])
    bboard("verify.json not JSON", lambda d: (d / "verify.json").write_text("{"), says=["verify.json"])
    bboard("verify.json counts as text", lambda d: (d / "verify.json").write_text(json.dumps(
        {"hash": "x", "runs": "2", "verified": "2", "failed": "0"})), says=["verify.json", "counts"])
    bboard("verify.json a folder", lambda d: (d / "verify.json").mkdir(), says=["verify.json"])
    bboard("verify.json honest (after verify)",
           lambda d: CliRunner().invoke(app, ["verify", str(d), *w1]), "accept", says=["board.md"])
    bboard("a floor's runs.csv without its floor column",
           lambda d: _edit_rows(_rows(d, f0), lambda r: r.drop(columns=["floor"])), says=["runs.csv", "floor"])
    bboard("a floor's runs.csv without its suite_hash column",
           lambda d: _edit_rows(_rows(d, f0), lambda r: r.drop(columns=["suite_hash"])), says=["runs.csv", "suite_hash"])
    bboard("a row duplicated", lambda d: _edit_rows(_rows(d, f0), lambda r: pd.concat([r, r.iloc[[0]]], ignore_index=True)),
           says=["twice"])
    bboard("a floor's runs.csv of garbage", lambda d: _rows(d, f0).write_bytes(b"\x00\xff" * 300), says=["runs.csv"])
    bboard("its floor folder removed", lambda d: shutil.rmtree(d / f0), says=["hold no rows"])
    board("an empty folder", [root / "empty"], says=["no bench.json"])
    board("a plain results folder", [results], says=["no bench.json"])
    board("a bench folder and a plain one", [b, results], says=["no bench.json"])
    board("a folder that does not exist", [root / "nowhere"], says=["no bench.json"])
    (root / "a-file").write_text("x")
    add("board", "--out a file", ["bench", "board", b, "--out", root / "a-file"], says=["--out"])

    # -- bench run, hash and list -------------------------------------------------------------------
    run = ["bench", "run", "doors-v1", "--planner", "greedy", "--workers", "1"]
    add("bench", "bench list", ["bench", "list"], "accept", says=["doors-v1"])
    add("bench", "run: an unknown suite", ["bench", "run", "doors-v2", "--planner", "greedy", "--out", out_dir()],
        says=["did you mean 'doors-v1'"])
    add("bench", "run: --limit 0", [*run, "--limit", "0", "--out", out_dir()], says=["--limit"])
    add("bench", "run: --limit -3", [*run, "--limit", "-3", "--out", out_dir()], says=["--limit"])
    add("bench", "run: --limit abc", [*run, "--limit", "abc", "--out", out_dir()], says=["--limit"])
    add("bench", "run: --limit 1.5", [*run, "--limit", "1.5", "--out", out_dir()], says=["--limit"])
    add("bench", "run: --out a plain results folder", [*run, "--limit", "1", "--out", copy(results, "plain")],
        says=["--out", "semsearch run", "never share"])
    d = copy(results, "plain")
    (d / "runs.csv").unlink()
    add("bench", "run: --out a plain folder with meta.json only", [*run, "--limit", "1", "--out", d], says=["--out", "meta.json"])
    add("bench", "run: --out inside a bench folder", [*run, "--limit", "1", "--out", copy(bench, "inside") / f0],
        says=["--out", "inside the bench folder"])
    add("bench", "run: --out a file", [*run, "--limit", "1", "--out", root / "a-file"], says=["--out"])
    add("bench", "run: --out a bench folder of another numbering",
        [*run, "--limit", "1", "--numbering", "shuffled", "--out", copy(bench, "numbering")], says=["numbering"])
    d = copy(bench, "badjson")
    (d / "bench.json").write_text("[]")
    add("bench", "run: --out a bench folder whose bench.json is a list", [*run, "--limit", "1", "--out", d],
        says=["bench.json"])
    d = copy(bench, "nohash")
    without("hash")(d)
    add("bench", "run: --out a bench folder whose bench.json lacks its hash", [*run, "--limit", "1", "--out", d],
        says=["bench.json", "hash"])
    d = copy(bench, "dirjson")
    (d / "bench.json").unlink()
    (d / "bench.json").mkdir()
    add("bench", "run: --out a folder whose bench.json is a folder", [*run, "--limit", "1", "--out", d], says=["bench.json"])
    add("bench", "run: --numbering sideways", [*run, "--limit", "1", "--numbering", "sideways", "--out", out_dir()],
        says=["--numbering", "sideways"])
    add("bench", "run: --numbering shufled (a typo)", [*run, "--limit", "1", "--numbering", "shufled", "--out", out_dir()],
        says=["did you mean 'shuffled'"])
    add("bench", "run: --split nope", [*run, "--limit", "1", "--split", "nope", "--out", out_dir()], says=["--split"])
    add("bench", "run: --split test without its salt", [*run, "--limit", "1", "--split", "test", "--out", out_dir()],
        says=["--salt-file"])
    add("bench", "run: --planner nsoss", [*run[:3], "--planner", "nsoss", "--limit", "1", "--out", out_dir()],
        says=["--planner", "did you mean 'nsos'"])
    add("bench", "run: --workers 0", [*run[:5], "--workers", "0", "--limit", "1", "--out", out_dir()], says=["--workers"])
    add("bench", "run (plain): --out a bench folder", ["run", scenario, *w1, "--out", copy(bench, "plainin")],
        says=["--out", "is a bench folder"])
    add("bench", "run (plain): --out a bench folder's floor", ["run", scenario, *w1, "--out", copy(bench, "plainin") / f0],
        says=["--out", "lies inside"])
    add("bench", "sweep: --out a bench folder", ["sweep", scenario, "--param", "experiment.max_distance=200,300", *w1,
                                                 "--out", copy(bench, "sweepin")], says=["--out", "bench folder"])
    hashed = ["bench", "hash", "doors-v1", "--split", "test", "--salt-file"]
    fifo = root / "salt.fifo"
    if not fifo.exists():
        os.mkfifo(fifo)
    add("bench", "hash: --salt-file a FIFO with no writer", [*hashed, fifo], says=["salt.fifo", "FIFO"], within=5)
    link = root / "salt.link"
    if not link.is_symlink():
        link.symlink_to(fifo)
    add("bench", "hash: --salt-file a symlink to a FIFO", [*hashed, link], says=["salt.link", "FIFO"], within=5)
    add("bench", "hash: --salt-file a folder", [*hashed, root / "empty"], says=["folder"])
    add("bench", "hash: --salt-file /dev/zero", [*hashed, "/dev/zero"], says=["/dev/zero", "device"], within=5)
    huge = root / "salt.huge"
    huge.write_text("s" * 100_000)
    add("bench", "hash: --salt-file of 100 kB", [*hashed, huge], says=["salt.huge", "bytes"])
    add("bench", "hash: --salt-file that does not exist", [*hashed, root / "nosalt"], says=["nosalt", "cannot read"])
    short = root / "salt.short"
    short.write_text("short\n")
    add("bench", "hash: --salt-file of 5 characters", [*hashed, short], says=["at least 16"])
    binary = root / "salt.bin"
    binary.write_bytes(b"\xff\xfe" * 20)
    add("bench", "hash: --salt-file not UTF-8", [*hashed, binary], says=["salt.bin", "cannot read"])
    add("bench", "hash: --salt-file for the public val split", ["bench", "hash", "doors-v1", "--salt-file", short],
        says=["--salt-file", "public"])
    add("bench", "hash: an unknown suite", ["bench", "hash", "doors-v9"], says=["doors-v9"])
    add("bench", "hash: doors-v1 val", ["bench", "hash", "doors-v1"], "accept")
    return cases
