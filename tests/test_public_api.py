"""The public API is a contract: its names are pinned here, and a name renamed keeps working for
at least one minor release with a DeprecationWarning that names its replacement."""

import inspect
import re
import subprocess
import sys
import textwrap

import pytest
import yaml

import semsearch_cli
from semsearch_cli import api, belief, planners
from semsearch_cli.belief import doors as belief_doors
from semsearch_cli.planners import base as planners_base

# what planner authors import (semsearch_cli.planners.__all__)
PLANNER_NAMES = ["PLANNERS", "Decision", "DoorContext", "DoorPlanner", "Goal", "IndirectContext", "IndirectPlanner",
                 "LsosParams", "NoParams", "ObjectContext", "ObjectPlanner", "Planner", "Told", "Variant", "code_of",
                 "expand_variants", "load_entry_points", "load_planner_file", "lsos_goals", "planner_class",
                 "register_planner"]
# the Python API: each function with its parameters in order
API = {
    "run": ["scenario", "options", "progress", "plots", "planner_specs"],
    "first_prompt": ["scenario", "options"],
    "report": ["folders", "out", "formats", "replay"],
    "sweep_alpha": ["scenario", "alphas", "options", "progress"],
    "sweep": ["scenario", "param", "values", "options", "progress"],
    "parse_param": ["text"],
    "write_summary": ["runs", "out_dir"],
    "record": ["scenario", "out", "cases"],
    "imported": ["importer", "out", "args", "kwargs"],
    "schema_text": [],
    "schema": ["out"],
    "validate": ["scenario"],
    "show": ["scenario", "out"],
    "episodes": ["scenario", "out"],
    "planners": ["scenario"],
    "scenarios": [],
    "default_out": ["loaded", "out"],
    "init": ["name", "folder", "force"],
    "verify": ["folder", "scenario", "progress", "workers", "salt_file", "allow_unrecorded"],
    "export": ["folder", "out", "fmt", "run", "scenario", "kept"],
    "ros_replay": ["bag", "planner", "out", "scenario", "fmt", "planner_file", "goal", "margin"],
    "ros_live": ["rosbridge", "planner", "goal", "scenario", "publish_only", "repro", "margin", "max_distance", "planner_file",
                 "silence", "log", "out"],
    "ros_sim": ["scenario", "goal", "seed", "port", "period", "follow"],
    "bench_run": ["suite", "planners", "out", "split", "numbering", "options", "limit", "salt_file", "planner_file", "progress"],
    "bench_list": [],
    "bench_hash": ["suite", "split", "salt_file"],
    "bench_fetch": ["suite", "from_dirs", "mirror", "partial", "progress"],
    "bench_board": ["folders", "out"],
    "llm_serve": ["model", "port", "threads", "context", "log"],
    "model_identity": ["server"],
    "planner_spec": ["text", "module"],
    "presence": ["counts", "hours", "out"],
    "generate_building": ["layout", "numbering", "seed", "out", "spacing", "signs", "goals", "name", "scale", "skip", "letters",
                          "extension", "style", "letter_case"],
    "generate_batch": ["out", "seeds", "runs", "layouts", "schemes"],
    "generate_rooms": ["n", "seed", "out", "size", "obstacles"],
    "import_mobilesim": ["map_file", "doors_file", "out", "options"],
    "import_ros": ["map_file", "doors_file", "out", "options"],
    "import_kth": ["xml_file", "out", "options"],
}
REMOVED = [(planners, "PlanContext"), (planners_base, "PlanContext"), (belief, "Belief"), (belief_doors, "Belief")]  # 0.3.0


def test_the_planner_api_names_are_pinned():
    assert sorted(planners.__all__) == sorted(PLANNER_NAMES)
    for name in PLANNER_NAMES:
        assert getattr(planners, name) is not None


def test_the_python_api_functions_and_their_parameters_are_pinned():
    # the package's functions, whichever of its feature modules holds each (semsearch_cli/api/)
    public = {n for n, f in vars(api).items() if inspect.isfunction(f) and f.__module__.startswith(api.__name__ + ".")
              and not n.startswith("_")}
    assert public == set(API) and set(API) <= set(api.__all__)
    for name, params in API.items():
        assert list(inspect.signature(getattr(api, name)).parameters) == params, name


def test_the_version_follows_semantic_versioning():
    """A release is MAJOR.MINOR.PATCH; main between releases is the next one's .dev0 (PEP 440, which
    package indexes take, unlike a local version)."""
    m = re.fullmatch(r"(\d+)\.(\d+)\.(\d+)(\.dev0)?", semsearch_cli.__version__)
    assert m and (int(m.group(1)), int(m.group(2))) >= (0, 2)


@pytest.mark.parametrize("module, old", REMOVED)
def test_the_names_deprecated_in_0_2_0_are_gone(module, old):
    """PlanContext and Belief warned through 0.2.0 and were removed in 0.3.0 (CHANGELOG "Removed")."""
    assert not hasattr(module, old)


OLD_PLANNER = '''
"""A door planner written against the API before 0.2.0: Planner with choose(ctx, cands)."""
from semsearch_cli.planners import Decision, Planner, register_planner


@register_planner("first_candidate")
class FirstCandidate(Planner):
    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        return Decision(int(cands.rows[0]), int(cands.cols[0]))
'''


def test_the_command_line_refuses_a_planner_written_against_the_api_removed_in_0_3_0(tmp_path, demo_dir):
    (tmp_path / "old_planner.py").write_text(OLD_PLANNER)
    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc["map"]["image"] = str(demo_dir / sc["map"]["image"])
    sc["doors"] = str(demo_dir / sc["doors"])
    sc["goals"] = sc["goals"][:1]
    sc["planners"] = [{"name": "first_candidate", "module": "old_planner.py"}]
    sc["experiment"] = {"seeds": 1, "max_distance": 300}
    (tmp_path / "old.yaml").write_text(yaml.safe_dump(sc))
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "run", str(tmp_path / "old.yaml"),
                          "--workers", "1", "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert res.returncode == 2, res.stderr
    assert "Traceback" not in res.stderr
    words = " ".join(res.stderr.split())
    assert "FirstCandidate answers no kind of search" in words and "removed in 0.3.0" in words and "subclass DoorPlanner" in words
    assert "old_planner.py" in words
    assert not (tmp_path / "out" / "runs.csv").exists()
