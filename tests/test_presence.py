"""Presence estimation (thesis 5.3.5, Eq. 5.3) against hand-computed values."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.belief.presence import hour_weight, presence_scores, read_counts

EXAMPLE = Path(__file__).resolve().parents[1] / "configs" / "hh106_counts.csv"


def test_hour_weight_on_the_24_hour_clock():
    assert hour_weight(10, 10) == 1.0
    assert hour_weight(10, 16) == 0.5
    assert hour_weight(0, 12) == 0.0
    assert hour_weight(23, 1) == pytest.approx(1 - 2 / 12)  # across midnight: 2 hours apart
    assert hour_weight(1, 23) == pytest.approx(1 - 2 / 12)
    assert hour_weight(0.5, 23.5) == pytest.approx(1 - 1 / 12)
    assert np.allclose(hour_weight(12, np.arange(24)), 1 - np.minimum(np.abs(np.arange(24) - 12), 24 - np.abs(np.arange(24) - 12)) / 12)


def test_scores_by_hand():
    counts = pd.DataFrame({"A": [2, 0, 1], "B": [0, 3, 0]}, index=[0.0, 6.0, 22.0])
    s = presence_scores(counts, [0, 6])
    # at 0:00: A = 2*1 + 0 + 1*(1 - 2/12); B = 3*(1 - 6/12)
    assert s.loc[0.0, "A"] == pytest.approx(2 + 10 / 12)
    assert s.loc[0.0, "B"] == pytest.approx(1.5)
    # at 6:00: A = 2*0.5 + 1*(1 - 8/12); B = 3
    assert s.loc[6.0, "A"] == pytest.approx(1 + 4 / 12)
    assert s.loc[6.0, "B"] == 3.0


def test_thesis_table_5_3_picks_the_places_of_its_last_day():
    s = presence_scores(read_counts(EXAMPLE), [1, 10, 16, 18, 22])
    # Table 5.4 (the held-out 60th day): bedroom at 1 and 22, O.D. at 10 and 16, W.A. at 18
    assert s.idxmax(axis=1).tolist() == ["BedR.", "O.D.", "O.D.", "W.A.", "BedR."]
    assert s.loc[1.0, "BedR."] == pytest.approx(219.667, abs=1e-3)


def test_presence_command_and_errors(tmp_path):
    res = CliRunner().invoke(app, ["presence", str(EXAMPLE), "--hours", "1,10", "--out", str(tmp_path / "p.csv")])
    assert res.exit_code == 0, res.output
    assert "219.67*" in res.output
    assert pd.read_csv(tmp_path / "p.csv")["highest"].tolist() == ["BedR.", "O.D."]
    res = CliRunner().invoke(app, ["presence", str(EXAMPLE), "--hours", "25"])
    assert res.exit_code == 2 and "--hours" in res.output
    bad = tmp_path / "bad.csv"
    bad.write_text("hour,A\n1,x\n")
    res = CliRunner().invoke(app, ["presence", str(bad), "--hours", "1"])
    assert res.exit_code == 2 and "bad.csv" in res.output
