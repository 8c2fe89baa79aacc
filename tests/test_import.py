"""MobileSim import on a small line map written here."""

import numpy as np
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.experiment import Loaded


def test_import_mobilesim_snaps_signs_and_runs(tmp_path):
    # a 20 m x 2 m corridor (mm), closed at both ends; signs 0.5 m behind its walls
    lines = ["0 0 20000 0", "20000 0 20000 2000", "20000 2000 0 2000", "0 2000 0 0"]
    (tmp_path / "c.map").write_text("2D-Map\nResolution: 0\nNumLines: 4\nLINES\n" + "\n".join(lines) + "\nDATA\n")
    (tmp_path / "c.doors").write_text("5.0 -0.5 1 90\n5.0 2.5 2 -90\n15.0 -0.5 3 90\n15.0 2.5 4 -90\n")
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["import", "mobilesim", str(tmp_path / "c.map"), str(tmp_path / "c.doors"),
                                   "--out", str(out), "--start", "2,1", "--goals", "3,4"])
    assert res.exit_code == 0, res.output
    L = Loaded.load(out / "scenario.yaml")
    s = L.world.signs
    # snapped onto the wall faces of the corridor, facing into it
    assert np.allclose(s.y, [0.05, 1.95, 0.05, 1.95], atol=0.06)
    assert np.allclose(np.degrees(s.facing), [90, -90, 90, -90])
    assert L.shortest[3] > 12.0 and L.shortest[4] > 12.0
    res = CliRunner().invoke(app, ["run", str(out / "scenario.yaml"), "--seeds", "1", "--workers", "1", "--out", str(tmp_path / "r")])
    assert res.exit_code == 0, res.output


def test_import_reports_bad_start(tmp_path):
    (tmp_path / "c.map").write_text("LINES\n0 0 1000 0\n1000 0 1000 1000\n1000 1000 0 1000\n0 1000 0 0\nDATA\n")
    (tmp_path / "c.doors").write_text("0.5 -0.2 1 90\n")
    res = CliRunner().invoke(app, ["import", "mobilesim", str(tmp_path / "c.map"), str(tmp_path / "c.doors"),
                                   "--out", str(tmp_path / "o"), "--start", "5,5"])
    assert res.exit_code == 2 and "--start" in res.output
