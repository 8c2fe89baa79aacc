"""A planner class from a user's file is checked when it registers: every class attribute the
simulator, the planner list or a report reads later (``Params``, ``rank``, ``swept``, ``__doc__``,
those a kind's protocol declares) is of the right kind, else exit 2 naming the file, the
``Class.attribute`` and the user's line, never a traceback after a whole batch. Errors at import
name the line of the user's file, not one of semsearch's. A decision's ``info`` that holds
itself is that run's ``error``. What lies beside a planner file named ``*.py`` but is no file
(a folder, a dangling symlink, a pipe) is left out of its code hash, and a pipe cannot hang it."""

import itertools
import os
import subprocess
import sys
import textwrap

import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.config import PlannerSpec
from semsearch_cli.errors import PlannerError, ScenarioError
from semsearch_cli.planners import PLANNERS, Decision, expand_variants, load_planner_file
from semsearch_cli.planners.base import MAX_INFO_DEPTH, check_planner_class
from semsearch_cli.provenance import files_hash, regular_bytes

HEAD = '''\
"""A user's planner."""
import math

from pydantic import BaseModel, Field, field_validator, model_validator

from semsearch_cli.planners import Decision, DoorPlanner, IndirectPlanner, register_planner


'''

# (the class, the field the error names, the text that marks the line it names, words of the message)
BAD = {
    "params_dict": ("class Bad(DoorPlanner):\n    Params = dict\n", "Params", "Params = dict", "Params = dict: give a pydantic model"),
    "params_none": ("class Bad(DoorPlanner):\n    Params = None\n", "Params", "Params = None", "Params = None"),
    "params_model_validator": ('''\
class Bad(DoorPlanner):
    class Params(BaseModel):
        a: float = 1.0

        @model_validator(mode="after")
        def check(self):
            raise ZeroDivisionError("no")
''', "Params", 'raise ZeroDivisionError("no")', "from their defaults raised ZeroDivisionError: no"),
    "params_field_validator": ('''\
class Bad(DoorPlanner):
    class Params(BaseModel):
        a: float = 1.0

        @field_validator("a")
        @classmethod
        def check(cls, v):
            return v / 0
''', "Params", "return v / 0", "from their defaults raised ZeroDivisionError: float division by zero"),
    "params_bad_default": ('''\
class Bad(DoorPlanner):
    class Params(BaseModel):
        a: float = Field(-1.0, ge=0.0)
''', "Params", "class Params", "defaults are not valid (a: Input should be greater than or equal to 0)"),
    "rank_text": ("class Bad(DoorPlanner):\n    rank = \"high\"\n", "rank", "rank = ", "rank = 'high': expected a finite number"),
    "rank_nan": ("class Bad(DoorPlanner):\n    rank = math.nan\n", "rank", "rank = ", "rank = nan: expected a finite number"),
    "rank_bool": ("class Bad(DoorPlanner):\n    rank = True\n", "rank", "rank = ", "expected a finite number"),
    "baseline_text": ("class Bad(DoorPlanner):\n    baseline = \"no\"\n", "baseline", "baseline = ", "expected True or False"),
    "task_number": ("class Bad(DoorPlanner):\n    task = 3\n", "task", "task = ", "task = 3: expected text"),
    "masks_number": ("class Bad(IndirectPlanner):\n    masks = 3\n", "masks", "masks = ", "masks = 3: expected text or None"),
    "swept_no_parameter": ('''\
class Bad(DoorPlanner):
    class Params(BaseModel):
        alpha: float = 0.9

    swept = "alhpa"
''', "swept", "swept = ", "swept = 'alhpa' names no parameter of the planner (did you mean 'alpha'?)"),
    "swept_default_none": ('''\
class Bad(DoorPlanner):
    class Params(BaseModel):
        alpha: float | None = None

    swept = "alpha"
''', "swept", "swept = ", "swept = 'alpha', whose default is None"),
    "doc_number": ("class Bad(DoorPlanner):\n    __doc__ = 42\n", "__doc__", "__doc__ = ", "__doc__ = 42: a planner's description"),
}

_names = itertools.count()


def planner_file(folder, body, name=None):
    """A planner file registering the class of ``body`` under a name no other test takes (one
    process registers a name once); returns (path, name)."""
    name = name or f"pc_{next(_names)}_{os.getpid()}"
    path = folder / f"{name}.py"
    path.write_text(HEAD + f'@register_planner("{name}")\n' + body)
    return path, name


def line_of(path, needle):
    return next(i for i, text in enumerate(path.read_text().splitlines(), 1) if needle in text)


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_planner_class_is_refused_when_it_registers_naming_file_field_and_line(tmp_path, case):
    body, attr, marker, words = BAD[case]
    path, name = planner_file(tmp_path, body)
    with pytest.raises(ScenarioError) as err:
        load_planner_file(path)
    e = err.value
    assert e.file == str(path) and e.field == f"Bad.{attr}", str(e)
    assert e.message.startswith(f"line {line_of(path, marker)} of {path.name}, planner class Bad: "), e.message
    assert words in e.message, e.message
    assert name not in PLANNERS
    with pytest.raises(ScenarioError) as again:  # not half loaded: loading it again says the same
        load_planner_file(path)
    assert str(again.value) == str(e)


def test_the_command_line_refuses_a_bad_class_with_exit_2_and_no_traceback(tmp_path, demo_dir):
    path, name = planner_file(tmp_path, BAD["swept_default_none"][0])
    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc["map"]["image"] = str(demo_dir / sc["map"]["image"])
    sc["doors"] = str(demo_dir / sc["doors"])
    sc["planners"] = [{"name": "greedy"}, {"name": name, "module": path.name}]
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sc))
    for args in (["validate", str(tmp_path / "s.yaml")], ["planners", str(tmp_path / "s.yaml")]):
        res = CliRunner().invoke(app, args)
        out = " ".join(res.output.split())
        assert res.exit_code == 2 and "Traceback" not in res.output, res.output
        assert f"{path.name}, field 'Bad.swept': line {line_of(path, 'swept = ')} of {path.name}" in out, out


def test_a_good_class_registers_and_every_built_in_one_passes(tmp_path):
    path, name = planner_file(tmp_path, '''\
class Good(DoorPlanner):
    """Fine: a required parameter, a swept one, a rank that is a float."""
    class Params(BaseModel):
        goal_weight: float
        alpha: float = 0.9

    rank = 2.5
    swept = "alpha"
    baseline = False

    def choose(self, ctx, cands):
        return None
''')
    assert load_planner_file(path) == [name]
    for cls in PLANNERS.values():
        check_planner_class(cls)


def test_a_file_that_raises_at_import_names_its_own_line_not_semsearchs(tmp_path):
    path = tmp_path / "dup.py"
    path.write_text(HEAD + '@register_planner("greedy")\nclass Dup(DoorPlanner):\n    pass\n')
    with pytest.raises(ScenarioError) as err:
        load_planner_file(path)
    assert err.value.file == str(path) and err.value.field == f"line {line_of(path, 'register_planner(')}"
    assert "'greedy' is already registered" in err.value.message
    (tmp_path / "helper_mod.py").write_text("def f():\n    return {}['missing']\n")
    path = tmp_path / "imports.py"
    path.write_text("import sys, os\nsys.path.insert(0, os.path.dirname(__file__))\nimport helper_mod\n\n\nhelper_mod.f()\n")
    try:
        with pytest.raises(ScenarioError) as err:
            load_planner_file(path)
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("helper_mod", None)
    assert err.value.field == "line 6", str(err.value)
    assert f"KeyError: 'missing' (raised at line 2 of {tmp_path / 'helper_mod.py'})" in err.value.message


def test_a_validator_that_raises_on_a_scenarios_value_names_the_scenario_and_the_users_line(tmp_path):
    path, name = planner_file(tmp_path, '''\
class Picky(DoorPlanner):
    class Params(BaseModel):
        a: float = 1.0

        @field_validator("a")
        @classmethod
        def check(cls, v):
            return 1 / (v - 2)

    def choose(self, ctx, cands):
        return None
''')
    spec = PlannerSpec(name=name, module=path.name, a=[1.0, 2.0])
    with pytest.raises(ScenarioError) as err:
        expand_variants([spec], file="s.yaml", task="doors", base=tmp_path)
    e = err.value
    assert e.file == "s.yaml" and e.field == "planners[0]"
    assert e.message == (f"planner {name!r} with a=2.0: its Params raised ZeroDivisionError: float division by zero "
                         f"(line {line_of(path, 'return 1 / (v - 2)')} of {path})")


def test_an_info_that_holds_itself_is_a_planner_error_saying_where():
    info = {"a": 1}
    info["me"] = info
    with pytest.raises(PlannerError, match=r"Decision.info holds itself: info\['me'\] is info;"):
        Decision(1, 2, info)
    inner = [1, {}]
    inner[1]["up"] = inner
    with pytest.raises(PlannerError, match=r"holds itself: info\['a'\]\[1\]\['up'\] is info\['a'\]"):
        Decision(1, 2, {"a": inner})
    deep = cur = {}
    for _ in range(MAX_INFO_DEPTH + 5):
        cur["d"] = {}
        cur = cur["d"]
    with pytest.raises(PlannerError, match=f"nested deeper than {MAX_INFO_DEPTH} levels"):
        Decision(1, 2, deep)
    with pytest.raises(PlannerError, match="Decision.info is list"):
        Decision(1, 2, [1, 2])
    shared = [1.0, 2.0]
    assert Decision(1, 2, {"a": shared, "b": shared, "c": (shared, {"d": shared})}).info["b"] is shared  # shared, not a loop


def test_a_run_whose_info_holds_itself_is_that_runs_error_and_the_trace_is_kept(tmp_path, demo_dir):
    path, name = planner_file(tmp_path, '''\
class Loop(DoorPlanner):
    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        info = {"a": 1}
        info["me"] = info
        return Decision(int(cands.rows[0]), int(cands.cols[0]), info)
''')
    from semsearch_cli.runner import Loaded, expand
    from semsearch_cli.runner.execution import Watch, execute

    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc["map"]["image"] = str(demo_dir / sc["map"]["image"])
    sc["doors"] = str(demo_dir / sc["doors"])
    sc["goals"] = sc["goals"][:1]
    sc["planners"] = [{"name": name, "module": path.name}]
    sc["experiment"] = {"seeds": 1, "max_distance": 100}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sc))
    loaded = Loaded.load(tmp_path / "s.yaml")
    spec = expand(loaded)[0]
    rows, res = execute(loaded, spec, Watch(trace=True))
    assert res.outcome == "error" and len(rows) == 1
    assert rows[0]["message"].startswith("PlannerError: Decision.info holds itself: info['me'] is info"), rows[0]["message"]


# ---- what lies beside a planner file ----------------------------------------------------------
JUNK = textwrap.dedent('''
    import os, sys
    from semsearch_cli.provenance import files_hash
    from semsearch_cli.planners import Variant, code_of, load_planner_file
    folder, planner = sys.argv[1], sys.argv[2]
    before = files_hash(__import__("pathlib").Path(folder), recursive=False)
    os.mkdir(os.path.join(folder, "junk.py"))
    os.symlink(os.path.join(folder, "nowhere"), os.path.join(folder, "dead.py"))
    os.symlink("loop.py", os.path.join(folder, "loop.py"))
    os.mkfifo(os.path.join(folder, "pipe.py"))
    after = files_hash(__import__("pathlib").Path(folder), recursive=False)
    name = load_planner_file(planner)[0]
    code = code_of(Variant(name, (), planner))
    print(before == after, code["source"], len(code["hash"]))
''')


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes on this system")
def test_a_folder_a_dangling_symlink_or_a_pipe_beside_a_planner_file_is_left_out_of_its_hash(tmp_path):
    path, _ = planner_file(tmp_path, "class Fine(DoorPlanner):\n    def choose(self, ctx, cands):\n        return None\n")
    (tmp_path / "helper.py").write_text("X = 1\n")
    # in a process of its own, with a time limit: a pipe opened for reading would wait forever
    res = subprocess.run([sys.executable, "-c", JUNK, str(tmp_path), str(path)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["True", "file", "16"]
    assert "junk.py" in os.listdir(tmp_path) and "pipe.py" in os.listdir(tmp_path)
    # the helper module beside it still counts
    before = files_hash(tmp_path, recursive=False)
    (tmp_path / "helper.py").write_text("X = 2\n")
    assert files_hash(tmp_path, recursive=False) != before


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes on this system")
def test_regular_bytes_reads_files_and_nothing_else_without_waiting(tmp_path):
    import threading

    (tmp_path / "f.py").write_bytes(b"x = 1\n")
    (tmp_path / "d.py").mkdir()
    os.mkfifo(tmp_path / "p.py")
    os.symlink(tmp_path / "f.py", tmp_path / "l.py")
    os.symlink(tmp_path / "gone", tmp_path / "dead.py")
    got = {}
    t = threading.Thread(target=lambda: got.update({n: regular_bytes(tmp_path / n) for n in
                                                    ("f.py", "d.py", "p.py", "l.py", "dead.py", "none.py")}), daemon=True)
    t.start()
    t.join(30)
    assert not t.is_alive(), "regular_bytes waited on a pipe"
    assert got == {"f.py": b"x = 1\n", "d.py": None, "p.py": None, "l.py": b"x = 1\n", "dead.py": None, "none.py": None}
