"""Hostile inputs for the surfaces the last release added (issue 35), in the spirit of
``tests/hostile_inputs.py``: one class per surface, each with its own cases and what must happen.

Classes: ``labels`` (goals and sign numbers: digits, length, ``304.0``, ``²``), ``episodes`` (an
episode set from a CSV, a list or drawn: its bound, its numbers, its hash column), ``output`` (the
files a run or a report writes, where something else stands), ``frames`` (the replay frames ``run
--frames`` writes, damaged on disk; ``--replay``), ``planners`` (a user's planner file and what
lies beside it) and ``commands`` (the Dask executor's flags, damaged rows, ``import ros``, an
indirect search's class names).

A case is a :class:`ReleaseCase`, the catalogue's :class:`~tests.hostile_inputs.Case` with two
fields more: ``fast`` (it runs in CI: ``tests/test_hostile_release.py`` runs every fast case
in-process; the others, which start a cluster or wait on a network, only in
``benchmarks/hostile.py --catalogue release``) and ``within`` (the seconds the case may take
as a process in the benchmark, for inputs that must be refused before any work on them: a 60,000-digit label, an
episodes file past its bound). ``issue`` stays False: it marks the first review's defects.

A case is refused when it exits with status 2 and no traceback, and its output holds each of
``says`` (the field, flag or file blamed); accepted when it exits 0.
"""

from __future__ import annotations

import io
import os
import re
import shutil
import zipfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.tasks.episodes import Episode

from .hostile_inputs import Case, _dump, _set, demo_base

CLASSES = ("labels", "episodes", "output", "frames", "planners", "commands")
GOAL = 304  # a sign of the demo building (maps/demo/doors.csv), one of its scenario's goals
LONG_DIGITS = "7" * 60_000  # a label of 60,000 digits: refused before any arithmetic on it


@dataclass
class ReleaseCase(Case):
    fast: bool = True  # run in CI (in-process); False: only in benchmarks/hostile.py
    within: float | None = None  # s the case may take as a process (refused before any work; benchmarks/hostile.py)


# a user's planner file: a door planner that takes the nearest frontier candidate
PLANNER_HEAD = '''\
"""A user's planner (hostile-input catalogue)."""
import numpy as np

from semsearch_cli.planners import Decision, DoorPlanner, register_planner


'''
NEAREST = '''\
    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        x, y = ctx.belief.frame.to_world(cands.rows, cands.cols)
        k = int(np.argmin(np.hypot(x - ctx.x, y - ctx.y)))
        return Decision(int(cands.rows[k]), int(cands.cols[k]), {})
'''


def results_with_frames(root: Path, scenario: Path) -> Path:
    """A real results folder of one run with its replay frames (``run --frames``), made once."""
    out = root / "results_frames"
    if not (out / "runs.csv").is_file():
        res = CliRunner().invoke(app, ["run", str(scenario), "--seeds", "1", "--workers", "1", "--frames", "--out", str(out)])
        if res.exit_code != 0 or not list((out / "frames").glob("*.npz")):
            raise RuntimeError(f"the results folder with frames could not be made: {res.output}")
    return out


def _npy_header_only(shape: tuple, dtype=np.uint8) -> bytes:
    """A .npy member whose header claims ``shape`` and which holds a few bytes of data."""
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": np.lib.format.dtype_to_descr(np.dtype(dtype)),
                                               "fortran_order": False, "shape": shape})
    return buf.getvalue() + b"\x00" * 16


def _damaged_frames(good: Path) -> dict:
    """Damaged copies of a frames file, by name: the bytes to write in its place."""
    with np.load(good) as z:
        arrays = {k: z[k] for k in z.files}

    def savez(d: dict, **kw) -> bytes:
        buf = io.BytesIO()
        np.savez(buf, **d, **kw)
        return buf.getvalue()

    three = {k: v for k, v in arrays.items() if k == "n" or int(k.split("/")[0]) < 3}
    big = io.BytesIO()
    with zipfile.ZipFile(big, "w") as zf:
        for k, v in arrays.items():
            member = io.BytesIO()
            np.lib.format.write_array(member, np.asarray(v))
            zf.writestr(f"{k}.npy", _npy_header_only((40000, 40000)) if k == "0/map" else member.getvalue())
    return {
        "an empty file": b"",
        "no key n": savez({k: v for k, v in arrays.items() if k != "n"}),
        "n = 10**9": savez({**arrays, "n": np.int64(10**9)}),
        "a key 5/map past n = 3": savez({**three, "n": np.int64(3), "5/map": arrays["0/map"]}),
        "0/path a text array": savez({**arrays, "0/path": np.array([["here", "there"]])}),
        "a pickled object array": savez({**arrays, "0/path": np.array([{"x": 1.0}, None], dtype=object)}, allow_pickle=True),
        "0/map's header claims 40000 x 40000 uint8": big.getvalue(),
        "a text file": b"not a zip file\n",
    }


def _frames_unlike_the_run(good: Path) -> list[tuple[str, bytes, str]]:
    """Copies of a door run's frames file, each well formed but with values no run of its scenario
    records (the replay drew them into a traceback, or drew them without a word): (name, the bytes
    to write in its place, the key the refusal names)."""
    with np.load(good) as z:
        arrays = {k: z[k] for k in z.files}

    def savez(**kw) -> bytes:
        buf = io.BytesIO()
        np.savez(buf, **{**arrays, **{k.replace("__", "/"): v for k, v in kw.items()}})
        return buf.getvalue()

    shape = arrays["0/map"].shape
    indirect = io.BytesIO()
    np.savez(indirect, n=np.int64(1), **{"0/p": np.full((5, 5), 0.04), "0/p0": np.float64(0.0), "0/trail": np.zeros((1, 2)),
                                         "0/t": np.float64(0.0), "0/goal": np.zeros(2)})
    return [("0/read holds a sign index past the scenario's 24 signs", savez(**{"0__read": np.array([10**6])}), "0/read"),
            ("0/read holds the index -1 (read as the last sign)", savez(**{"0__read": np.array([-1])}), "0/read"),
            ("0/read holds 1.5", savez(**{"0__read": np.array([1.5])}), "0/read"),
            ("0/path of no pose", savez(**{"0__path": np.zeros((0, 2))}), "0/path"),
            ("0/path of NaN", savez(**{"0__path": np.full((3, 2), np.nan)}), "0/path"),
            ("0/distance -1", savez(**{"0__distance": np.float64(-1.0)}), "0/distance"),
            ("0/map of 3 x 3 cells (another scenario's)", savez(**{"0__map": np.zeros((3, 3), np.uint8)}), "0/map"),
            ("0/map of 7s", savez(**{"0__map": np.full(shape, 7, np.uint8)}), "0/map"),
            ("an indirect search's frame in a door run's file", indirect.getvalue(), "0/")]


def build_cases(root: Path) -> list[ReleaseCase]:
    """Every case of the release catalogue, its files written under ``root`` (one results folder
    with frames is made by a real run, ~2 s)."""
    root.mkdir(parents=True, exist_ok=True)
    base, demo = demo_base(root)
    base = _set(base, ["goals"], [GOAL])
    good = _dump(root / "good.yaml", base)
    cases: list[ReleaseCase] = []
    out = root / "out"  # refused runs write nothing; an accepted one writes here

    def out_dir() -> Path:
        """An output folder of the next case's own (the benchmark runs cases side by side)."""
        return out / f"case{len(cases)}"

    def add(category, name, args, expect="refuse", says=(), fast=True, within=None):
        assert category in CLASSES, category
        cases.append(ReleaseCase(category, name, [str(a) for a in args], expect, False, tuple(says), fast=fast, within=within))

    def folder(category: str, name: str) -> Path:
        d = root / category / re.sub(r"[^A-Za-z0-9_.-]+", "_", name)[:60]
        d.mkdir(parents=True, exist_ok=True)
        return d

    def scen(category: str, name: str, data) -> Path:
        return _dump(folder(category, name) / "scenario.yaml", data)

    def raw_scen(category: str, name: str, text: str) -> Path:
        """A scenario written as text: YAML spellings safe_dump would not write (yes, 1_5)."""
        p = folder(category, name) / "scenario.yaml"
        p.write_text(text)
        return p

    run = ["--seeds", "1", "--workers", "1"]

    # -- labels: goals and sign numbers ----------------------------------------------------------
    for name, goal, says in (("a goal of 20 digits", 12345678901234567890, ["digits", "goals"]),
                             ("a goal label of 300 characters", "k" * 300, ["64 characters", "goals"]),
                             ('an empty goal ""', "", ["empty", "goals"])):
        add("labels", name, ["validate", scen("labels", name, _set(base, ["goals"], [goal]))], says=says)
    # a YAML integer of 60,000 digits: Python's int() of its text refuses it (past 4,300 digits)
    text = yaml.safe_dump(_set(base, ["goals"], []), sort_keys=False).replace("goals: []", f"goals: [{LONG_DIGITS}]")
    add("labels", "a goal of 60,000 digits in YAML", ["validate", raw_scen("labels", "goal60000", text)], says=["goals"], within=10)
    for name, goal, says in (("--goal of 20 digits", "12345678901234567890", ["--goal", "digits"]),
                             ("--goal of 60,000 digits", LONG_DIGITS, ["--goal"]),
                             ("--goal ²", "²", ["--goal"]), ("--goal 30²", "30²", ["--goal"])):
        add("labels", name, ["run", good, *run, "--goal", goal, "--out", out_dir()], says=says, within=10 if len(goal) > 100 else None)
    # --goal read as a CSV's column of labels (sign_label's docs: 148.0 is the number 148), as goals: [304.0] is
    add("labels", "--goal 304.0 (a goal written 304.0 in YAML is 304)", ["run", good, *run, "--goal", f"{GOAL}.0", "--out", out_dir()],
        "accept")
    add("labels", "--goal 304.0,305 (a column of mixed forms is text)", ["run", good, *run, "--goal", f"{GOAL}.0,305", "--out", out_dir()],
        says=["--goal", "304.0"])
    add("labels", "--goal ３０４ (full-width digits)", ["run", good, *run, "--goal", "３０４", "--out", out_dir()], says=["--goal"])
    for name, goal, expect, says in (("a goal -304", -304, "refuse", ["goals[0]"]),
                                     ("a goal 304 with a zero-width space", "304\u200b", "refuse", ["goals[0]", "control"]),
                                     ("a goal '+304'", "+304", "accept", []), ("a goal ' 304 ' (spaces)", " 304 ", "accept", []),
                                     ("a goal 304 with a no-break space", "304\u00a0", "accept", [])):
        add("labels", name, ["validate", scen("labels", name, _set(base, ["goals"], [goal]))], expect, says)
    dtext = (demo / "doors.csv").read_text()
    doors = folder("labels", "doors304.0") / "doors.csv"
    doors.write_text(re.sub(r"(?m)^(\d+),", r"\1.0,", dtext))  # a spreadsheet's column of numbers: 304.0
    assert "304.0," in doors.read_text()
    add("labels", "a doors CSV whose numbers read 304.0, goal 304",
        ["validate", scen("labels", "doors304.0", _set(base, ["doors"], str(doors)))], "accept")
    add("labels", "a goal written 304.0 in YAML", ["validate", scen("labels", "goal304.0", _set(base, ["goals"], [304.0]))], "accept")
    add("labels", "goals ['304'] as text in YAML", ["validate", scen("labels", "goal_text", _set(base, ["goals"], ["304"]))], "accept")
    # MobileSim: a 20 m x 2 m corridor, signs 0.5 m behind its walls (tests/test_import.py)
    ms = folder("labels", "mobilesim")
    walls = ["0 0 20000 0", "20000 0 20000 2000", "20000 2000 0 2000", "0 2000 0 0"]
    (ms / "c.map").write_text("2D-Map\nLINES\n" + "\n".join(walls) + "\nDATA\n")
    for name, number, expect, says in (("a .doors number ²", "²", "either", []),
                                       ("a .doors number of 60,000 digits", LONG_DIGITS, "refuse", ["c_", ".doors", "line 2"])):
        f = ms / f"c_{len(cases)}.doors"
        f.write_text(f"5.0 -0.5 1 90\n5.0 2.5 {number} -90\n15.0 -0.5 3 90\n15.0 2.5 4 -90\n")
        add("labels", f"import mobilesim, {name}", ["import", "mobilesim", ms / "c.map", f, "--out", out_dir(), "--start", "2,1",
                                                    "--goals", "3"], expect, says, within=10)

    # -- episodes: from a CSV, a list, drawn -----------------------------------------------------
    def episodes_csv(name: str, text: str, expect="refuse", says=(), within=None):
        d = folder("episodes", name)
        (d / "eps.csv").write_text(text)
        p = _dump(d / "scenario.yaml", _set(base, ["episodes"], {"file": "eps.csv"}))
        add("episodes", name, ["validate", p], expect, says, within=within)

    head = "goal,start_x,start_y,start_heading\n"
    row = f"{GOAL},15.0,10.0,0.0\n"
    episodes_csv("150,001 rows (the bound is 100,000)", head + row * 150_001, says=["eps.csv", "100,000"], within=15)
    episodes_csv("start_x of 1_5", head + f"{GOAL},1_5,10.0,0.0\n", says=["eps.csv", "line 2"])
    episodes_csv("start_x of ١٥ (Arabic-Indic digits)", head + f"{GOAL},١٥,10.0,0.0\n", says=["eps.csv", "line 2"])
    episodes_csv("a row of 5 fields under a 4-field header", head + row + f"{GOAL},15.0,10.0,0.0,7\n",
                 says=["eps.csv", "line 3", "5 fields"])
    episodes_csv("start_y nan", head + f"{GOAL},15.0,nan,0.0\n", says=["eps.csv", "line 2", "finite"])
    episodes_csv("a goal of 60,000 digits", head + f"{LONG_DIGITS},15.0,10.0,0.0\n", says=["eps.csv", "line 2"], within=10)
    right = Episode(0, GOAL, 15.0, 10.0, 0.0, None).hash
    episodes_csv("a hash that is not the episode's", head.replace("\n", ",hash\n") + row.replace("\n", ",0123456789abcdef\n"),
                 says=["eps.csv", "hash"])
    episodes_csv("the episode's own hash", head.replace("\n", ",hash\n") + row.replace("\n", f",{right}\n"), "accept")
    episodes_csv("the hash of an edited row (start_x moved)", head.replace("\n", ",hash\n") + f"{GOAL},16.0,10.0,0.0,{right}\n",
                 says=["eps.csv", "hash"])
    episodes_csv("a goal written 304.0", head + f"{GOAL}.0,15.0,10.0,0.0\n", "accept")
    # the columns and the numbers of each row, named where they are wrong
    episodes_csv("a column start_headng (misspelt: every heading was drawn at random)",
                 head.replace("start_heading", "start_headng") + row, says=["eps.csv", "start_headng", "'start_heading'"])
    episodes_csv("a column colour", head.replace("\n", ",colour\n") + row.replace("\n", ",red\n"), says=["eps.csv", "colour"])
    episodes_csv("the column goal twice in the header", "goal,start_x,start_y,goal\n304,15,10,305\n", says=["eps.csv", "given twice"])
    episodes_csv("episode 0 on two lines", "episode," + head + f"0,{row}0,{GOAL},16.0,10.0,0.0\n", says=["eps.csv", "line 3 episode"])
    episodes_csv("an episode column of abc", "episode," + head + f"abc,{row}", says=["eps.csv", "line 2 episode"])
    episodes_csv("start_heading 1e9 (episodes.list takes -3600 to 3600)", head + f"{GOAL},15.0,10.0,1e9\n",
                 says=["eps.csv", "line 2 start_heading", "3600"])
    episodes_csv("start_heading Random", head + f"{GOAL},15.0,10.0,Random\n", says=["eps.csv", "line 2 start_heading"])
    episodes_csv("start_x empty", head + f"{GOAL},,10.0,0.0\n", says=["eps.csv", "line 2 start_x"])
    episodes_csv("a room kitchen in a door scenario's episodes", head.replace("\n", ",room\n") + row.replace("\n", ",kitchen\n"),
                 says=["eps.csv", "line 2 room"])
    episodes_csv("a header Goal (capitalised)", head.replace("goal", "Goal") + row, says=["eps.csv", "'Goal'"])
    episodes_csv("a file of semicolons", head.replace(",", ";") + row.replace(",", ";"), says=["eps.csv", "';'"])
    episodes_csv("a byte-order mark and CRLF line ends", ("\ufeff" + head + row).replace("\n", "\r\n"), "accept")
    own = Episode(0, GOAL, 15.0, 10.0, 0.0, None, 11.73).row()
    episodes_csv("the eight columns semsearch episodes writes", ",".join(own) + "\n" + ",".join(str(v) for v in own.values()) + "\n",
                 "accept")
    base_text = yaml.safe_dump(base, sort_keys=False)
    add("episodes", "episodes: {starts: yes} (YAML 1.1 true)",
        ["validate", raw_scen("episodes", "starts_yes", base_text + "episodes: {starts: yes}\n")], says=["episodes.starts"])
    add("episodes", "episodes: {starts: 1_0} (YAML 1.1 reads 10)",
        ["validate", raw_scen("episodes", "starts_1_0", base_text + "episodes: {starts: 1_0}\n")], says=["episodes.starts"])
    add("episodes", "episodes.list, x: 1_5 unquoted",
        ["validate", raw_scen("episodes", "list_1_5", base_text + f"episodes: {{list: [{{goal: {GOAL}, x: 1_5, y: 10.0}}]}}\n")],
        says=["episodes.list[0].x"])
    add("episodes", "episodes.starts 100,001 (past the bound)",
        ["validate", scen("episodes", "starts_big", _set(base, ["episodes"], {"starts": 100_001}))], says=["episodes.starts"])

    # -- output: what a run or a report writes, where something else stands ------------------------
    for name, what, flag, make in (("paths is a file", "paths", [], "file"), ("traces is a file (--trace)", "traces", ["--trace"], "file"),
                                   ("frames is a file (--frames)", "frames", ["--frames"], "file"),
                                   ("summary.csv is a folder", "summary.csv", [], "folder"),
                                   ("runs.csv is a folder", "runs.csv", [], "folder"), ("meta.json is a folder", "meta.json", [], "folder"),
                                   ("figures is a file", "figures", [], "file")):
        o = folder("output", name) / "O"
        o.mkdir(exist_ok=True)
        if make == "file":
            (o / what).write_text("x")
        else:
            (o / what).mkdir(exist_ok=True)
        add("output", f"run --out O where O/{name}", ["run", good, *run, *flag, "--out", o], says=[what])
    frames_scen = _dump(root / "frames_scenario.yaml", base)
    results = results_with_frames(root, frames_scen)
    frame_file = sorted((results / "frames").glob("*.npz"))[0]
    rows = pd.read_csv(results / "runs.csv")
    first = rows.iloc[0]
    replay = f"{first['planner']},{first['goal']},{first['episode']},{first['seed']}"

    def results_copy(category: str, name: str) -> Path:
        """A copy of the results folder, with its scenario where its meta.json finds it (../)."""
        d = folder(category, name) / "R"
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(results, d)
        shutil.copy(frames_scen, d.parent / frames_scen.name)
        return d

    d = results_copy("output", "report.md is a folder")
    (d / "report.md").unlink()
    (d / "report.md").mkdir()
    add("output", "report where report.md is a folder", ["report", d, "--no-replay"], says=["report.md"])
    d = results_copy("output", "tables is a file")
    shutil.rmtree(d / "tables")
    (d / "tables").write_text("x")
    add("output", "report where tables is a file", ["report", d, "--no-replay"], says=["tables"])

    # -- frames: a run's replay frames, damaged on disk -------------------------------------------
    for name, data in _damaged_frames(frame_file).items():
        d = results_copy("frames", name)
        (d / "frames" / frame_file.name).write_bytes(data)
        add("frames", f"frames file: {name}", ["report", d, "--replay", replay], says=[frame_file.name], within=30)
    for name, data, key in _frames_unlike_the_run(frame_file):
        d = results_copy("frames", name)
        (d / "frames" / frame_file.name).write_bytes(data)
        add("frames", f"frames file: {name}", ["report", d, "--replay", replay, "--format", "md"], says=[frame_file.name, key])
    # --replay's goal as check_replay reads it (304.0 is the goal 304): the section found no run and
    # drew none, exit 0; it reads the run's frames (here damaged, so refused)
    d = results_copy("frames", "replay 304.0")
    (d / "frames" / frame_file.name).write_bytes(b"not a zip file\n")
    add("frames", f"--replay {first['planner']},{first['goal']}.0,... reads that run's frames",
        ["report", d, "--replay", f"{first['planner']},{first['goal']}.0,{first['episode']},{first['seed']}", "--format", "md"],
        says=[frame_file.name])
    d = results_copy("frames", "replay_ok")
    add("frames", "the undamaged frames replay", ["report", d, "--replay", replay], "accept")
    for value in ("greedy,452,0,--1", "greedy,452,0,²", "greedy,452,٠,0", f"greedy,452,0,{LONG_DIGITS}"):
        add("frames", f"--replay {value[:24]}", ["report", results_copy("frames", "replay_text"), "--replay", value], says=["--replay"],
            within=10)

    # -- planners: a user's planner file, and what lies beside it -----------------------------------
    def planner_case(name: str, body: str, expect="refuse", says=(), register=None, beside=None, command="validate",
                     planners=None, prelude=""):
        d = folder("planners", name)
        reg = register or f"hostile_release_{len(cases)}"
        (d / "p.py").write_text(PLANNER_HEAD + prelude + f"@register_planner({reg!r})\n" + body)
        for junk in beside or ():
            junk(d)
        doc = _set(base, ["planners"], planners or [{"name": reg, "module": "p.py"}])
        p = _dump(d / "scenario.yaml", doc)
        args = ["validate", p] if command == "validate" else ["run", p, *run, "--out", out_dir()]
        add("planners", name, args, expect, says)

    for attr in ("Params = dict", 'rank = "high"', 'swept = "nope"', "__doc__ = 42"):
        planner_case(attr, f"class Mine(DoorPlanner):\n    {attr}\n" + NEAREST, says=["p.py", f"Mine.{attr.split()[0]}"])
    good_body = "class Mine(DoorPlanner):\n    \"\"\"Nearest candidate.\"\"\"\n" + NEAREST
    for name, junk, make in (("a folder junk.py beside p.py", "junk.py", os.mkdir),
                             ("a dangling symlink dead.py beside p.py", "dead.py", lambda f: os.symlink(f.with_name("nowhere"), f)),
                             ("a FIFO pipe.py beside p.py", "pipe.py", os.mkfifo)):
        planner_case(name, good_body, "accept", beside=[lambda d, j=junk, m=make: (d / j).is_symlink() or (d / j).exists() or m(d / j)],
                     command="run")
    planner_case("a planner named nsos[alpha=0.9]", good_body, says=["p.py", "a name holds only"], register="nsos[alpha=0.9]")
    planner_case("a planner named nsos_alpha0.9 beside {name: nsos, alpha: 0.9}", good_body, says=["planners", "nsos_alpha0.9"],
                 register="nsos_alpha0.9", planners=[{"name": "nsos", "alpha": 0.9}, {"name": "nsos_alpha0.9", "module": "p.py"}])
    planner_case("a planner name of 300 characters", good_body, says=["p.py", "at most 64 characters"], register="m" * 300)
    # a Params model's defaults, and the parameters a scenario gives it
    pyd = "from pydantic import BaseModel, ConfigDict, Field\n\n\n"
    def params(field: str) -> str:
        return "class Mine(DoorPlanner):\n    \"\"\"Nearest candidate.\"\"\"\n\n    class Params(BaseModel):\n        " + field + "\n\n" + NEAREST

    planner_case("Params: a default_factory of -5 for a field ge=0 (was taken unchecked)",
                 params("k: int = Field(default_factory=lambda: -5, ge=0)"), says=["p.py", "Mine.Params", "k"], prelude=pyd)
    planner_case("Params: a default of float('nan')", params("k: float = float('nan')"), says=["p.py", "Mine.Params", "nan"],
                 prelude=pyd)
    planner_case("Params: a valid default_factory", params("k: list = Field(default_factory=lambda: [1, 2])"), "accept",
                 prelude=pyd)
    planner_case("a parameter kk the Params does not take (pydantic ignores it: the run used k's default)",
                 params("k: int = 1"), says=["planners[0].kk", "'k'"], register="hostile_release_kk", prelude=pyd,
                 planners=[{"name": "hostile_release_kk", "module": "p.py", "kk": 2}])
    planner_case("a parameter given by its alias K", params("k: int = Field(1, alias='K')"), "accept",
                 register="hostile_release_alias", prelude=pyd, planners=[{"name": "hostile_release_alias", "module": "p.py", "K": 2}])
    planner_case("a Params of extra='allow' takes any key", params("model_config = ConfigDict(extra='allow')"), "accept",
                 register="hostile_release_allow", prelude=pyd, planners=[{"name": "hostile_release_allow", "module": "p.py", "kk": 2}])
    planner_case("rank = 10**400 (past a float)", "class Mine(DoorPlanner):\n    rank = 10**400\n" + NEAREST,
                 says=["p.py", "Mine.rank", "a finite number"])
    planner_case("cost_columns = ('colour',) (the batch wrote the column, then refused its runs.csv)",
                 "class Mine(DoorPlanner):\n    cost_columns = ('colour',)\n" + NEAREST, says=["p.py", "Mine.cost_columns", "colour"])
    d = folder("planners", "nul")
    (d / "p.py").write_bytes(PLANNER_HEAD.encode() + b"x = 1\x00\n")
    add("planners", "a planner file holding a NUL byte (was blamed on 'line None')",
        ["validate", _dump(d / "scenario.yaml", _set(base, ["planners"], [{"name": "mine", "module": "p.py"}]))],
        says=["p.py: not valid Python"])
    for name, up in (("module: ../../../../etc/passwd", 4), ("module: ../ up to the root, then etc/passwd (a file, not Python)", None)):
        d = folder("planners", name)
        up = up or len(d.resolve().parts) - 1  # enough to reach / from the scenario's folder
        p = _dump(d / "scenario.yaml", _set(base, ["planners"], [{"name": "mine", "module": "../" * up + "etc/passwd"}]))
        add("planners", name, ["validate", p], says=["module"])

    # -- commands: the Dask executor, damaged rows, import ros, indirect class names -----------------
    for address, fast in (("notanaddress", True), ("tcp://:99999", True), ("tcp://127.0.0.1:1", False)):
        add("commands", f"--executor dask --scheduler {address}",
            ["run", good, "--seeds", "1", "--executor", "dask", "--scheduler", address, "--out", out_dir()], says=["--scheduler"],
            fast=fast, within=10 if fast else None)
    add("commands", "--executor dask --workers 1 (a local cluster)", ["run", good, *run, "--executor", "dask", "--out", out_dir()],
        "accept", fast=False)
    d = results_copy("commands", "runs.csv with a column colour")
    r = pd.read_csv(d / "runs.csv", dtype=str, keep_default_na=False)
    r["colour"] = "red"
    r.to_csv(d / "runs.csv", index=False)
    add("commands", "report: runs.csv with an extra column", ["report", d, "--no-replay"], says=["runs.csv", "colour"])
    for value in ("nan", "inf", "-1"):
        d = results_copy("commands", f"found distance {value}")
        r = pd.read_csv(d / "runs.csv", dtype=str, keep_default_na=False)
        assert (r["outcome"] == "found").any()
        r.loc[r["outcome"] == "found", "distance_m"] = value
        r.to_csv(d / "runs.csv", index=False)
        add("commands", f"report: a found run of distance_m {value}", ["report", d, "--no-replay"], says=["runs.csv", "distance_m"])
    # sweep --param read as a scenario's YAML is (ScenarioLoader), --alphas as a person writes numbers
    for value, says in (("9" * 5000, ["--param", "laser.beams", "5,000 characters"]), ("1_81", ["--param", "1_81"]),
                        ("010", ["--param", "010"])):
        add("commands", f"sweep --param laser.beams={value[:12]} (yaml.safe_load read {'its int' if len(value) > 9 else 'a number'})",
            ["sweep", good, *run, "--param", f"laser.beams={value}", "--out", out_dir()], says=says)
    add("commands", "sweep-alpha --alphas ٠.٥ (Arabic-Indic digits: float() read 0.5)",
        ["sweep-alpha", good, *run, "--alphas", "٠.٥", "--out", out_dir()], says=["--alphas"])
    d = results_copy("commands", "one folder twice")
    add("commands", "report of one folder given twice (its rows counted twice)", ["report", d, f"{d}/.", "--no-replay",
                                                                                    "--out", out_dir()], says=["FOLDERS", "twice"])
    add("commands", "--planner gredy names the nearest", ["run", good, *run, "--planner", "gredy", "--out", out_dir()],
        says=["--planner", "'greedy'"])
    ros = folder("commands", "ros")
    room = np.zeros((40, 60), np.uint8)
    room[2:-2, 2:-2] = 254
    for name, pgm in (("room", room), ("three", np.full((3, 3), 254, np.uint8))):
        cv2.imwrite(str(ros / f"{name}.pgm"), pgm)
        (ros / f"{name}.yaml").write_text(f"image: {name}.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                                          "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    (ros / "doors5.csv").write_text("number,x,y,facing\n101,1.0,1.0,0\n\n102,2.0,0.5,90,7\n")
    add("commands", "import ros: a doors row of 5 fields", ["import", "ros", ros / "room.yaml", ros / "doors5.csv", "--out", out_dir()],
        says=["doors5.csv", "line 4", "5 fields"])
    add("commands", "import ros --clean of a 3 x 3 map", ["import", "ros", ros / "three.yaml", demo / "doors.csv", "--clean",
                                                          "--out", out_dir()], says=["three.yaml", "fits nowhere"])
    add("commands", "import ros of a 3 x 3 map", ["import", "ros", ros / "three.yaml", demo / "doors.csv", "--out", out_dir()],
        says=["three.yaml", "fits nowhere"])
    for name, section, says in (("indirect.relations names keybaord", {"relations": {"keybaord": [0.7, 0.1, 0.1, 0.1]}},
                                 ["indirect.relations.keybaord", "'keyboard'"]),
                                ("indirect.target moniter", {"target": "moniter"}, ["indirect.target", "'monitor'"])):
        doc = {"kind": "indirect", "name": "hostile", "indirect": {"rooms": {"count": 1, "seed": 0}, **section},
               "planners": [{"name": "UIS"}], "experiment": {"seeds": 1}}
        add("commands", name, ["validate", scen("commands", name, doc)], says=says)
    shutil.rmtree(out, ignore_errors=True)
    return cases
