"""The release's hostile inputs (issue 35; the catalogue is tests/hostile_release.py), the fast ones
run in-process: a refused input exits 2 with one paragraph naming the field, flag or file and no
traceback; an accepted one exits 0; nothing is written into the working folder. ``benchmarks/hostile.py --catalogue release``
runs every case, the slow ones too, as real processes, and times them (a case's ``within``).

Each case runs under guards, so that a defect fails its test and nothing else: an alarm (a hang
is a failure, not a stuck suite), a cap on the address space (a damaged file asking for 10**9
frames is a MemoryError, not the machine's memory), and the planner registry as it was (a user's
planner a case registers is forgotten after it)."""

from __future__ import annotations

import os
import resource
import signal
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

import pytest
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.planners import PLANNERS
from semsearch_cli.planners.base import _LOADED_FILES

from .hostile_inputs import check_outcome
from .hostile_release import CLASSES, build_cases

_TMP = tempfile.TemporaryDirectory(prefix="semsearch-hostile-release-")
ALL = build_cases(Path(_TMP.name) / "cases")
CASES = [c for c in ALL if c.fast]
runner = CliRunner()
HANG_S = 120  # a case still running after this is a hang
EXTRA_BYTES = 3 << 30  # address space a case may take beyond the test process's own


def test_every_class_of_the_issue_has_its_own_cases():
    for cls in CLASSES:
        mine = [c for c in ALL if c.category == cls]
        assert len(mine) >= 3, cls
        assert any(c.fast for c in mine), f"{cls}: no case runs in CI"
        assert {c.expect for c in mine} & {"refuse"}, cls
    assert {c.category for c in ALL} == set(CLASSES)
    assert len({(c.category, c.name) for c in ALL}) == len(ALL), "two cases share a name"
    assert all(c.says for c in ALL if c.expect == "refuse"), "a refusal must name what it refuses"


@contextmanager
def guarded():
    """An alarm at HANG_S, an address space of at most the process's own plus EXTRA_BYTES, and
    the planner registry restored afterwards."""
    planners, loaded, modules = dict(PLANNERS), dict(_LOADED_FILES), set(sys.modules)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    vm = next(int(line.split()[1]) * 1024 for line in Path("/proc/self/status").read_text().splitlines() if line.startswith("VmSize:"))
    cap = vm + EXTRA_BYTES if hard == resource.RLIM_INFINITY else min(vm + EXTRA_BYTES, hard)

    def hang(signum, frame):
        raise TimeoutError(f"still running after {HANG_S} s")

    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(HANG_S)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
        for name in set(PLANNERS) - set(planners):
            del PLANNERS[name]
        PLANNERS.update(planners)
        _LOADED_FILES.clear()
        _LOADED_FILES.update(loaded)
        for name in set(sys.modules) - modules:
            if name.startswith("semsearch_user_planners"):
                del sys.modules[name]


def run_guarded(case, tmp_path: Path) -> None:
    """Run a case's command in-process, in the empty folder ``tmp_path``, under :func:`guarded`,
    and check its outcome (tests/hostile_inputs.check_outcome)."""
    os.chdir(tmp_path)  # the working folder: nothing may be written here
    try:
        with guarded():
            res = runner.invoke(app, case.args)
    finally:
        os.chdir(Path(__file__).resolve().parents[1])
    check_outcome(case, res, tmp_path)


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="the address-space guard reads /proc")
@pytest.mark.parametrize("case", CASES, ids=[f"{c.category}: {c.name}" for c in CASES])
def test_hostile_input(case, tmp_path):
    run_guarded(case, tmp_path)
