"""Every defect of issues 14 and 26 as a case of the hostile-input catalogue (tests/hostile_inputs.py),
run in-process: a refused input exits 2 with one paragraph naming the file and the field (or the
flag) and no traceback; an accepted one exits 0; nothing is written into the working folder.
``benchmarks/hostile.py`` runs the whole catalogue as real processes."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest
from typer.testing import CliRunner

from semsearch_cli.cli import app

from .hostile_inputs import build_cases, check_outcome

_TMP = tempfile.TemporaryDirectory(prefix="semsearch-hostile-")
CASES = [c for c in build_cases(Path(_TMP.name) / "cases") if c.issue]
runner = CliRunner()


def test_the_catalogue_holds_every_group_of_the_issue():
    assert {c.category for c in CASES} == {"numbers", "files", "structure", "output", "markup", "command line", "resources",
                                           "commands", "importers", "planners"}
    assert len(CASES) >= 65


@pytest.mark.parametrize("case", CASES, ids=[f"{c.category}: {c.name}" for c in CASES])
def test_hostile_input(case, tmp_path):
    os.chdir(tmp_path)  # the working folder: nothing may be written here
    try:
        res = runner.invoke(app, case.args)
    finally:
        os.chdir(Path(__file__).resolve().parents[1])
    check_outcome(case, res, tmp_path)
