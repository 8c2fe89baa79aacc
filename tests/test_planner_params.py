"""Errors on planner parameters name the entry and the parameter (issue 52, item 5), one way from
the command line (bench run --planner, a run's --planner filter, sweep --param) and from a
scenario (field planners[i].<param>): ``'nsos[alpha=2]': alpha must be at most 1``."""

from __future__ import annotations

import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app

runner = CliRunner()

CASES = [  # (label, what the error says after the entry)
    ("nsos[alpha=2]", "alpha must be at most 1"),
    ("numbering[sigma=0]", "sigma must be more than 0"),
    ("bvp[coarsen=2.5]", "coarsen must be a whole number"),
    ("bvp[window=wide]", "window must be a number"),
    ("draft[beta=inf]", "beta must be a finite number"),
    ("nsos[w_g=nan]", "w_g must be a finite number"),
    ("nsos[door_bins=True]", "door_bins must be a number, not true or false"),
    ("nsos[door_bins=1000000000000]", "door_bins must be at most 3600"),
    ("lsos[sector=181]", "sector must be at most 180"),
    ("ISCG-PN-HM[visited=far]", "visited must be one of 'seen' or 'near'"),
    ("llm[timeout_s=0]", "timeout_s must be more than 0"),
    ("nsos[alpah=0.5]", "'nsos' has no parameter 'alpah' (did you mean 'alpha'?)"),
    ("greedy[alpha=1]", "'greedy' has no parameter 'alpha'"),
]


def text(res) -> str:
    assert res.exit_code == 2 and "Traceback" not in res.output, res.output
    return " ".join(res.output.split())


@pytest.mark.parametrize("label, says", CASES)
def test_a_planner_parameter_on_the_command_line_is_named(tmp_path, label, says):
    out = text(runner.invoke(app, ["bench", "run", "doors-v1", "--planner", label, "--limit", "1", "--out", str(tmp_path / "b")]))
    assert f"field '--planner': '{label}': {says}" in out
    assert not (tmp_path / "b").exists()  # refused before the folder is made
    out = text(runner.invoke(app, ["run", "demo", "--planner", f"greedy,{label}", "--out", str(tmp_path / "r")]))
    assert f"field '--planner': '{label}': {says}" in out and not (tmp_path / "r").exists()


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    d = tmp_path_factory.mktemp("demo")
    api.init("demo", d / "demo", force=True)
    return d / "demo" / "demo.yaml"


@pytest.mark.parametrize("entry, field, says", [
    ({"name": "nsos", "alpha": 2}, "alpha", "'nsos[alpha=2]': alpha must be at most 1"),
    ({"name": "numbering", "sigma": 0}, "sigma", "'numbering[sigma=0]': sigma must be more than 0"),
    ({"name": "nsos", "alpha": [0.5, 2]}, "alpha", "'nsos[alpha=2]': alpha must be at most 1"),
    ({"name": "nsos", "alpha": None}, "alpha", "'nsos[alpha=None]': alpha must be a number (it is empty)"),
    ({"name": "nsos", "alpha": float("nan")}, "alpha", "'nsos[alpha=nan]': alpha must be a finite number"),
    ({"name": "bvp", "coarsen": "two"}, "coarsen", "'bvp[coarsen=two]': coarsen must be a whole number"),
    ({"name": "nsos", "alfa": 0.5}, "alfa", "'nsos[alfa=0.5]': 'nsos' has no parameter 'alfa' (did you mean 'alpha'?)"),
])
def test_a_planner_parameter_in_a_scenario_is_named_with_its_field(demo, tmp_path, entry, field, says):
    d = yaml.safe_load(demo.read_text())
    d["planners"] = [{"name": "greedy"}, entry]
    p = demo.with_name(f"p_{field}.yaml")
    p.write_text(yaml.safe_dump(d))
    out = text(runner.invoke(app, ["validate", str(p)]))
    assert f"field 'planners[1].{field}': {says}" in out


def test_sweep_param_names_the_parameter(demo, tmp_path):
    d = yaml.safe_load(demo.read_text())
    d["planners"] = [{"name": "nsos"}]
    p = demo.with_name("sweep.yaml")
    p.write_text(yaml.safe_dump(d))
    out = text(runner.invoke(app, ["sweep", str(p), "--param", "nsos.alpha=0.5,2", "--out", str(tmp_path / "s")]))
    assert "field '--param': nsos.alpha=2 (planners[0].alpha of the scenario): 'nsos[alpha=2]': alpha must be at most 1" in out
    assert not (tmp_path / "s").exists()
