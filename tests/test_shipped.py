"""The shipped scenarios and maps are package data: listed, run by name and copied to edit from
any folder, and found by a wheel installed outside the checkout (the gym ids too)."""

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import __version__, shipped
from semsearch_cli.engine import ENGINE
from semsearch_cli.cli import app
from semsearch_cli.runner import Loaded

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def test_the_checkouts_configs_and_maps_are_the_shipped_ones():
    assert (ROOT / "configs").resolve() == shipped.CONFIGS and (ROOT / "maps").resolve() == shipped.MAPS
    assert {"demo", "hotel", "office", "indirect_quick", "hospital"} <= set(shipped.names())


def test_scenarios_lists_each_with_its_kind(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["scenarios"])
    assert res.exit_code == 0, res.output
    lines = {ln.split("│")[1].strip(): ln.split("│")[2].strip() for ln in res.output.splitlines()
             if ln.startswith("│") and ln.split("│")[1].strip()}
    assert lines["hotel"] == "doors" and lines["office"] == "objects" and lines["hospital"] == "chain"
    assert lines["indirect"] == "indirect" and set(lines) == set(shipped.names())


def test_a_shipped_scenario_by_name_from_any_folder_and_a_mistyped_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["validate", "demo"])
    assert res.exit_code == 0 and "signs: 24" in res.output, res.output
    res = runner.invoke(app, ["run", "demo", "--goal", "304", "--seeds", "1", "--workers", "1", "--planner", "greedy"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "results" / "demo" / "runs.csv").is_file()  # results in the working folder, not the package
    res = runner.invoke(app, ["run", "hotle"])
    assert res.exit_code == 2
    assert "'hotle' is neither a scenario file nor a shipped scenario (did you mean 'hotel'?)" in " ".join(res.output.split())


def test_a_name_that_is_also_a_copy_in_the_working_folder_is_refused_and_a_folder_does_not_shadow_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "demo").mkdir()  # a folder of that name is not a scenario: the name still runs the shipped one
    assert runner.invoke(app, ["validate", "demo"]).exit_code == 0
    assert runner.invoke(app, ["init", "demo", "."]).exit_code == 0
    res = runner.invoke(app, ["validate", "demo"])
    text = " ".join(res.output.split())
    assert res.exit_code == 2 and "'demo' is both a shipped scenario and demo.yaml in this folder" in text
    res = runner.invoke(app, ["validate", "demo.yaml"])
    assert res.exit_code == 0 and "signs: 24" in res.output


def test_init_copies_a_scenario_with_its_files_rewritten_to_the_copies(tmp_path):
    res = runner.invoke(app, ["init", "hotel", str(tmp_path / "mine")])
    assert res.exit_code == 0, res.output
    mine = tmp_path / "mine"
    assert sorted(p.relative_to(mine).as_posix() for p in mine.rglob("*") if p.is_file()) == [
        "hotel.yaml", "maps/hotel/doors.csv", "maps/hotel/map.png", "scenario.schema.json"]
    doc = yaml.safe_load((mine / "hotel.yaml").read_text())
    assert doc["map"]["image"] == "maps/hotel/map.png" and doc["doors"] == "maps/hotel/doors.csv"
    assert (mine / "hotel.yaml").read_text().startswith("# yaml-language-server: $schema=scenario.schema.json")
    assert Loaded.load(mine / "hotel.yaml").fingerprint == Loaded.load(shipped.path("hotel")).fingerprint
    (mine / "hotel.yaml").write_text((mine / "hotel.yaml").read_text() + "# mine now\n")
    res = runner.invoke(app, ["init", "hotel", str(mine)])
    assert res.exit_code == 2 and "already exists" in res.output and "--force" in res.output
    assert runner.invoke(app, ["init", "hotel", str(mine), "--force"]).exit_code == 0
    # a second scenario over the same map joins the folder: identical files are no clash
    res = runner.invoke(app, ["init", "hotel_thesis", str(mine)])
    assert res.exit_code == 0, res.output
    assert Loaded.load(mine / "hotel_thesis.yaml").fingerprint == Loaded.load(shipped.path("hotel_thesis")).fingerprint


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """A wheel built from a copy of the checkout (as a user builds one), once for this module."""
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: the wheel would carry no commit")
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    shutil.copytree(ROOT, src, symlinks=True, ignore=shutil.ignore_patterns(
        ".venv", "venv", "results", "build", "*.egg-info", "__pycache__", ".pytest_cache", ".hypothesis", "site"))
    wheels = tmp / "wheels"
    # without build isolation: the build backend is the test extra's setuptools, so this needs no network
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(wheels),
                            str(src)], capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-2000:]
    (whl,) = wheels.glob("semsearch-*.whl")
    head = subprocess.run(["git", "-C", str(src), "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    return whl, head


def test_a_wheel_installed_outside_the_checkout_finds_the_scenarios_the_gym_ids_and_its_commit(wheel, tmp_path):
    pytest.importorskip("gymnasium")
    wheel, head = wheel
    assert wheel.name.startswith(f"semsearch-{__version__}-")  # a plain release: indexes refuse local versions
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)], check=True,
                   capture_output=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    code = ("import gymnasium, semsearch_cli, semsearch_cli.envs\n"
            "from semsearch_cli.provenance import git_commit\n"
            "env = gymnasium.make('semsearch/DoorSearch-Hotel-v1')\n"
            "obs, info = env.reset(seed=0)\n"
            "print(semsearch_cli.__file__); print(git_commit()); print(env.unwrapped.task.kind)\n")
    env = {**os.environ, "PYTHONPATH": str(site)}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=elsewhere, env=env)
    assert res.returncode == 0, res.stderr
    where, commit, kind = res.stdout.split()
    assert Path(where).is_relative_to(site) and commit.split("+")[0] == head and kind == "doors"
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "validate", "kth"],
                         capture_output=True, text=True, cwd=elsewhere, env=env)
    assert res.returncode == 0 and "kth: ok" in res.stdout, res.stderr
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "--version"],
                         capture_output=True, text=True, cwd=elsewhere, env=env)
    assert res.stdout.startswith(f"semsearch {__version__} (engine {ENGINE}, code ") and f"commit {head}" in res.stdout, res.stdout
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "bench", "list"],
                         capture_output=True, text=True, cwd=elsewhere, env=env)
    assert res.returncode == 0 and "doors-real-v1" in res.stdout, res.stdout + res.stderr


def test_the_wheel_holds_every_data_file_the_code_opens(wheel, tmp_path, monkeypatch):
    """The package data is every file tracked under semsearch_cli/data/ (the wheel adds only the
    commit it was built from), and every file that the commands which read package data open there
    (an audit hook records each open) is in the wheel: a glob in pyproject.toml that leaves a
    file out fails here, not on a user's machine."""
    wheel, _ = wheel
    held = {n.removeprefix("semsearch_cli/data/") for n in zipfile.ZipFile(wheel).namelist() if n.startswith("semsearch_cli/data/")}
    data = ROOT / "semsearch_cli" / "data"
    tracked = subprocess.run(["git", "ls-files", "."], cwd=data, capture_output=True, text=True, check=True).stdout.split()
    assert held - set(tracked) == {"build_commit.txt"} and set(tracked) - held == set()
    opened: set[str] = set()

    def hook(event, args):
        if event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
            p = Path(os.fsdecode(args[0])).resolve()
            if p.is_relative_to(data.resolve()) and p.is_file():
                opened.add(p.relative_to(data.resolve()).as_posix())

    sys.addaudithook(hook)  # for the rest of the session; it records only opens under data/
    monkeypatch.chdir(tmp_path)
    # a cache of its own: `bench list` reads sources.json only for a track this machine has not fetched
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    for args in (["bench", "list"], ["scenarios"], ["planners"], ["validate", "hotel"], ["validate", "hospital"],
                 ["validate", "indirect_quick"], ["validate", "office"], ["init", "hotel", "mine"],
                 ["bench", "run", "doors-v1", "--planner", "learned", "--limit", "1", "--out", "b"]):
        res = runner.invoke(app, args)
        assert res.exit_code == 0, (args, res.output)
    assert "bench/doors-real-v1/sources.json" in opened  # what 0.2.0's wheel lacked (a model read before the hook is cached)
    assert sorted(opened - held) == []


def test_the_package_data_holds_no_half_written_folder():
    """A suite split is written as <split>.<pid>.tmp and renamed; one left behind is not data."""
    data = ROOT / "semsearch_cli" / "data"
    tracked = subprocess.run(["git", "ls-files", str(data)], cwd=ROOT, capture_output=True, text=True)
    paths = tracked.stdout.splitlines() if tracked.returncode == 0 else [str(p) for p in data.rglob("*")]
    assert not [p for p in paths if ".tmp/" in p or p.endswith(".tmp")]
