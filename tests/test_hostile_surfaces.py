"""The hostile catalogue of issue 52 (tests/hostile_surfaces.py: the robot, bench and llm surfaces),
the fast cases run in-process under the guards of tests/test_hostile_release.py (an alarm, a cap
on the address space, the planner registry restored): a refusal exits 2 with one paragraph naming
what it refuses, an acceptance exits 0, a check that finds its input wrong (verify of a falsified
folder) exits 1 saying what; never a traceback or a hang. ``benchmarks/hostile.py --catalogue
surfaces`` runs every case as a real process."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed: the robot surface's bags need it")
from .hostile_surfaces import CLASSES, build_cases  # noqa: E402
from .test_hostile_release import run_guarded  # noqa: E402

_TMP = tempfile.TemporaryDirectory(prefix="semsearch-hostile-surfaces-")
ALL = build_cases(Path(_TMP.name) / "cases")
CASES = [c for c in ALL if c.fast]


def test_the_catalogue_covers_every_class_with_at_least_150_cases():
    assert len(ALL) >= 150
    for cls in CLASSES:
        mine = [c for c in ALL if c.category == cls]
        assert len(mine) >= 3 and any(c.fast for c in mine), cls
    assert {c.category for c in ALL} == set(CLASSES)
    assert len({(c.category, c.name) for c in ALL}) == len(ALL), "two cases share a name"
    assert all(c.says for c in ALL if c.expect in ("refuse", "fail")), "a refusal must name what it refuses"


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="the address-space guard reads /proc")
@pytest.mark.parametrize("case", CASES, ids=[f"{c.category}: {c.name}" for c in CASES])
def test_hostile_input(case, tmp_path):
    run_guarded(case, tmp_path)
