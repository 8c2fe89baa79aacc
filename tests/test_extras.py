"""Optional packages never break the base install: with every extra's packages hidden (as after a
fresh ``pip install .``) the CLI starts, and each command that needs an extra refuses in one line
naming it, exit 2, before it writes anything."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from semsearch_cli.errors import MissingExtra
from semsearch_cli.kernels import COMPILING
from semsearch_cli.optional import installed, lazy_module

ROOT = Path(__file__).resolve().parents[1]
BARE = ROOT / "tests" / "bare.py"


def bare(*args, cwd):
    """semsearch ARGS with the extras hidden (tests/bare.py), in a subprocess."""
    return subprocess.run([sys.executable, str(BARE), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=300)


def test_a_dotted_name_whose_package_is_absent_is_none_not_an_import_error():
    # find_spec("absent.sub") imports "absent" and raises; lazy_module looks at the top level only
    assert lazy_module("semsearch_no_such_package.sub.module", "ros") is None
    assert not installed("semsearch_no_such_package.sub")
    assert installed("json.decoder") and installed("json")


def test_a_package_too_old_to_hold_the_sub_module_names_the_extra_at_first_use():
    mod = lazy_module("json.semsearch_no_such_sub_module", "llm")
    assert mod is not None  # json is there: nothing is imported yet
    with pytest.raises(MissingExtra) as info:
        mod.anything
    assert str(info.value).startswith("semsearch's use of json.semsearch_no_such_sub_module needs the llm extra: "
                                      "pip install 'semsearch[llm]' (ModuleNotFoundError")


def test_a_lazy_module_imports_at_first_attribute_access():
    mod = lazy_module("json.tool", "ros")
    assert mod.main.__module__ == "json.tool"


def test_the_base_install_starts_and_lists(tmp_path):
    res = bare("--version", cwd=tmp_path)
    assert res.returncode == 0 and res.stdout.startswith("semsearch "), res.stderr
    for args in (["--help"], ["bench", "list"], ["scenarios"], ["planners"], ["ros", "--help"], ["export", "--help"]):
        res = bare(*args, cwd=tmp_path)
        assert res.returncode == 0 and "Traceback" not in res.stderr, (args, res.stderr)


@pytest.mark.parametrize("args, line", [
    (["export", "results/x", "--out", "bags"], "error: semsearch export needs the ros extra: pip install 'semsearch[ros]'"),
    (["ros", "replay", "bag", "--planner", "greedy", "--out", "o"], "error: semsearch ros replay needs the ros extra: pip install 'semsearch[ros]'"),
    (["ros", "live", "--rosbridge", "ws://127.0.0.1:9", "--planner", "greedy", "--goal", "304"],
     "error: semsearch ros live needs the ros extra: pip install 'semsearch[ros]'"),
    (["ros", "sim", "demo", "--goal", "304"], "error: semsearch ros sim needs the ros extra: pip install 'semsearch[ros]'"),
    (["run", "demo", "--seeds", "1", "--executor", "dask", "--out", "r"], "error: --executor dask needs the dask extra: pip install 'semsearch[dask]'"),
    (["llm", "serve"], "error: semsearch llm serve needs the llm-local extra: pip install 'semsearch[llm-local]' (no module llama_cpp)"),
])
def test_a_command_that_needs_an_extra_refuses_in_one_line_naming_it(tmp_path, args, line):
    res = bare(*args, cwd=tmp_path)
    assert res.returncode == 2 and res.stderr.strip() == line, res.stderr
    assert not (tmp_path / "r").exists() and not (tmp_path / "bags").exists() and not (tmp_path / "o").exists()


NOTE_BATCH = """
import sys
from semsearch_cli.kernels import announce_compiling
from semsearch_cli.runner import BatchOptions, Loaded, expand, run_batch
from semsearch_cli.shipped import path
announce_compiling()
loaded = Loaded.load(path("demo"))
run_batch(loaded, expand(loaded, 2, None, ["greedy"]), __import__("pathlib").Path(sys.argv[1]), BatchOptions(workers=2, start_method="spawn",
          executor=sys.argv[2]))
"""


@pytest.mark.parametrize("executor", ["processes", "dask"])
def test_the_compiling_note_is_said_once_per_batch_not_once_per_worker(tmp_path, executor):
    """A cold numba cache (a folder of its own) and workers that start afresh (spawn; a Dask local
    cluster): each of them compiles, and the note is said once; with the cache warm, not at all."""
    if executor == "dask":
        pytest.importorskip("distributed")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": str(ROOT)}  # this checkout's code
    cmd = [sys.executable, "-c", NOTE_BATCH]
    res = subprocess.run([*cmd, str(tmp_path / "r"), executor], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    assert res.stderr.count(COMPILING) == 1, res.stderr
    res = subprocess.run([*cmd, str(tmp_path / "r2"), executor], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600)
    assert res.returncode == 0 and COMPILING not in res.stderr, res.stderr
