"""The front end of examples/front_end.py (docs/decisions.md, "A front end of your own"): an
episode opened and stepped from outside in about 40 lines, run as a script and as a module."""

import importlib.util
import subprocess
import sys
from pathlib import Path


FILE = Path(__file__).resolve().parents[1] / "examples" / "front_end.py"


def example():
    spec = importlib.util.spec_from_file_location("front_end", FILE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_example_is_a_page_long_and_runs_as_a_script(tmp_path):
    assert len(FILE.read_text().splitlines()) <= 45
    r = subprocess.run([sys.executable, str(FILE), "demo", "452"], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[-1].startswith("found after ") and lines[0].startswith("at (") and "frontier targets" in lines[0]


def test_its_user_answers_every_decision_and_the_run_is_the_same_each_time():
    fe = example()
    shown, asked = [], []

    def pick(ctx, cands):
        asked.append(len(cands))
        return fe.nearest(ctx, cands)

    row = fe.main("demo", "304", pick=pick, show=shown.append)
    assert row["outcome"] == "found" and row["planner"] == "user" and row["decisions"] > 0 and len(asked) > 0
    assert len(shown) == len(asked) + 1 and row == {**fe.main("demo", "304", show=lambda _: None), "wall_s": row["wall_s"]}
    # a user who only ever looks at walls: the run ends, as every decision was answered
    end = fe.main("demo", "304", pick=lambda ctx, cands: None, show=lambda _: None)
    assert end["outcome"] in ("found", "not_found", "stuck", "budget") and end["decisions"] > 0
