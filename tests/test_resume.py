"""Resume is exact: a run is keyed by the text its row was written with, so however a goal label
is written (4.50, 1e3, NA, K202, 2.10), running a batch again into its folder runs nothing and
leaves the rows as they were. (The batch alone: summaries and reports of such labels are their
own concern.)"""

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from semsearch_cli.config.base import sign_label
from semsearch_cli.planners import register_planner
from semsearch_cli.cli import app
from semsearch_cli.runner import BatchOptions, Loaded, expand, run_batch

# labels a spreadsheet or a person writes that a CSV reader takes for numbers or for missing values
TRICKY = ["4.50", "2.10", "1e3", "NA", "nan", "N/A", "None", "null", "inf", "-0.0", "1.0e2", "K202", "24D", "2.14"]
LABELS = st.one_of(st.sampled_from(TRICKY), st.from_regex(r"[1-9][0-9]{0,2}\.[0-9]0", fullmatch=True),
                   st.from_regex(r"[1-9]e[1-9]", fullmatch=True), st.from_regex(r"[A-Z][0-9]{1,3}", fullmatch=True))


def _text(runs_csv: Path) -> pd.DataFrame:
    """runs.csv as the text it holds, cell by cell."""
    return pd.read_csv(runs_csv, dtype=str, keep_default_na=False)


def _scenario(demo_dir: Path, folder: Path, labels: list[str]) -> Path:
    """The demo building with its first signs relabelled ``labels``, which are also its goals."""
    shutil.copy(demo_dir / "map.png", folder / "map.png")
    lines = (demo_dir / "doors.csv").read_text().splitlines()
    rows = [",".join([lab, *r.split(",")[1:]]) for lab, r in zip(labels, lines[1:])] + lines[1 + len(labels):]
    (folder / "doors.csv").write_text("\n".join([lines[0], *rows]) + "\n")
    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc.update(map={**sc["map"], "image": "map.png"}, doors="doors.csv", goals=list(labels), planners=[{"name": "greedy"}],
              experiment={"seeds": 1, "max_distance": 120.0})
    path = folder / "scenario.yaml"
    path.write_text(yaml.safe_dump(sc))
    return path


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(st.lists(LABELS, min_size=1, max_size=3, unique_by=lambda s: str(sign_label(s))))
def test_running_again_runs_nothing_and_leaves_the_rows(demo_dir, labels):
    if any(isinstance(sign_label(lab), int) for lab in labels):  # a whole number may be another sign's
        return
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        path = _scenario(demo_dir, folder, labels)
        out = folder / "out"
        loaded = Loaded.load(path)
        run_batch(loaded, expand(loaded, 1), out, BatchOptions(workers=1))
        first = _text(out / "runs.csv")
        assert sorted(first["goal"]) == sorted(str(sign_label(lab)) for lab in labels)
        run_batch(Loaded.load(path), expand(loaded, 1), out, BatchOptions(workers=1))
        again = _text(out / "runs.csv")
        assert len(again) == len(first) == len(labels)
        assert again.drop(columns="wall_s").equals(first.drop(columns="wall_s"))  # nothing ran again or was rewritten
        assert not again[["planner", "goal", "episode", "seed"]].duplicated().any()


def test_a_planner_name_that_reads_as_a_variant_label_is_refused():
    for name in ("nsos[alpha=0.9]", "a,b", "with space", "x" * 65, ""):
        with pytest.raises(TypeError, match="a name holds only letters, digits and"):
            register_planner(name)


SAME_FILES = '''
from semsearch_cli.planners import Decision, DoorPlanner, register_planner


@register_planner("nsos_alpha0.9")
class Clash(DoorPlanner):
    def choose(self, ctx, cands):
        return None
'''


def test_two_variants_that_would_share_their_runs_files_are_refused_when_the_scenario_loads(demo_dir, tmp_path):
    (tmp_path / "clash.py").write_text(SAME_FILES)
    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc.update(map={**sc["map"], "image": str(demo_dir / "map.png")}, doors=str(demo_dir / "doors.csv"),
              planners=[{"name": "nsos", "alpha": 0.9}, {"name": "nsos_alpha0.9", "module": "clash.py"}])
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sc))
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "validate", str(tmp_path / "s.yaml")],
                         capture_output=True, text=True)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert ("field 'planners': 'nsos[alpha=0.9]' and 'nsos_alpha0.9' would write their runs' files under one name"
            in " ".join(res.stderr.split())), res.stderr


GREEDY_AS = '''
from semsearch_cli.planners import register_planner
from semsearch_cli.planners.doors.greedy import Greedy


@register_planner({name!r})
class Mine(Greedy):
    """Greedy, under a name of the user's."""
'''
_DRAWN = iter(range(10 ** 6))  # a fresh prefix per example: a name registers once per process


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(st.from_regex(r"[A-Za-z0-9._+-]{1,40}", fullmatch=True), st.sampled_from(["K202", "4.50", "NA", "2.10"]))
def test_a_users_planner_under_any_valid_name_resumes_exactly(demo_dir, name, label):
    name = f"u{next(_DRAWN)}{name}"
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        path = _scenario(demo_dir, folder, [label])
        (folder / "mine.py").write_text(GREEDY_AS.format(name=name))
        sc = yaml.safe_load(path.read_text())
        sc["planners"] = [{"name": "greedy"}, {"name": name, "module": "mine.py"}]
        path.write_text(yaml.safe_dump(sc))
        out = folder / "out"
        loaded = Loaded.load(path)
        run_batch(loaded, expand(loaded, 1), out, BatchOptions(workers=1))
        first = _text(out / "runs.csv")
        assert sorted(first["planner"]) == sorted(["greedy", name]) and set(first["goal"]) == {label}
        run_batch(Loaded.load(path), expand(loaded, 1), out, BatchOptions(workers=1))
        again = _text(out / "runs.csv")
        assert again.drop(columns="wall_s").equals(first.drop(columns="wall_s"))


FAILING = '''
import os
from semsearch_cli.errors import Unavailable
from semsearch_cli.planners import register_planner
from semsearch_cli.planners.doors.greedy import Greedy


@register_planner({svc!r})
class Service(Greedy):
    """Greedy behind a service that is down while the file DOWN exists."""

    def choose(self, ctx, cands):
        if os.path.exists({down!r}):
            raise Unavailable("the service at 127.0.0.1:9 did not answer")
        return super().choose(ctx, cands)


@register_planner({broken!r})
class Broken(Greedy):
    """A planner that fails on its own: its exception is its result."""

    def choose(self, ctx, cands):
        raise RuntimeError("a bug of the planner's own")
'''


def _failing(demo_dir, tmp_path, svc="u_service", broken="u_broken"):
    """The demo building with planners ``svc`` (down while DOWN exists) and ``broken`` (a name
    registers once per process); (scenario, DOWN)."""
    for f in ("map.png", "doors.csv"):
        shutil.copy(demo_dir / f, tmp_path / f)
    down = tmp_path / "DOWN"
    down.touch()
    (tmp_path / "mine.py").write_text(FAILING.format(down=str(down), svc=svc, broken=broken))
    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc.update(map={**sc["map"], "image": "map.png"}, doors="doors.csv", goals=["304"], experiment={"seeds": 1, "max_distance": 120.0},
              planners=[{"name": svc, "module": "mine.py"}, {"name": broken, "module": "mine.py"}])
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(sc))
    return path, down


def test_resume_runs_again_what_failed_for_a_cause_outside_the_run_and_keeps_what_failed_on_its_own(demo_dir, tmp_path):
    path, down = _failing(demo_dir, tmp_path)
    out = tmp_path / "out"
    loaded = Loaded.load(path)
    run_batch(loaded, expand(loaded, 1), out, BatchOptions(workers=1))
    first = _text(out / "runs.csv").set_index("planner")
    assert first.loc["u_service", "outcome"] == "error"
    assert first.loc["u_service", "message"] == "unavailable: the service at 127.0.0.1:9 did not answer"
    assert first.loc["u_broken", "outcome"] == "error" and first.loc["u_broken", "message"].startswith("RuntimeError: a bug")
    run_batch(Loaded.load(path), expand(loaded, 1), out, BatchOptions(workers=1))  # still down: retried, fails again
    assert _text(out / "runs.superseded.csv")["planner"].tolist() == ["u_service"]
    down.unlink()
    run_batch(Loaded.load(path), expand(loaded, 1), out, BatchOptions(workers=1))
    again = _text(out / "runs.csv").set_index("planner")
    assert sorted(again.index) == ["u_broken", "u_service"]  # one row each: nothing duplicated, nothing dropped
    assert again.loc["u_service", "outcome"] == "found"
    kept, was = again.loc["u_broken"].drop("wall_s"), first.loc["u_broken"].drop("wall_s")
    # kept as it was, not run again (a missing number reads back missing: nan then, empty once rows were moved aside)
    assert kept.replace("nan", "").to_dict() == was.replace("nan", "").to_dict()
    assert _text(out / "runs.superseded.csv")["planner"].tolist() == ["u_service", "u_service"]


def test_a_batch_with_runs_that_could_not_run_ends_with_status_1_saying_so(demo_dir, tmp_path):
    path, down = _failing(demo_dir, tmp_path, "u_service2", "u_broken2")
    res = CliRunner().invoke(app, ["run", str(path), "--workers", "1", "--out", str(tmp_path / "out")])
    said = " ".join(res.output.split())
    assert res.exit_code == 1, said
    assert ("1 run(s) could not run, for a cause outside them (e.g. u_service2: unavailable: the service at 127.0.0.1:9 did "
            "not answer): they are not results; once the cause is fixed, the same command runs them again") in said
    down.unlink()
    res = CliRunner().invoke(app, ["run", str(path), "--workers", "1", "--out", str(tmp_path / "out")])
    assert res.exit_code == 0 and "could not run" not in res.output, res.output
