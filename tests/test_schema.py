"""`semsearch schema`: the scenario format as a JSON Schema, shipped beside the configs and named by
their first line, so that an editor completes and checks a scenario as it is typed."""

import json
from pathlib import Path

import jsonschema
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.config import KINDS

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "configs" / "scenario.schema.json"
LINE = "# yaml-language-server: $schema=scenario.schema.json"
CONFIGS = sorted((ROOT / "configs").glob("*.yaml"))


def test_the_schema_has_one_branch_per_kind():
    schema = json.loads(api.schema_text())
    branches = [schema["$defs"][b["$ref"].rsplit("/", 1)[1]] for b in schema["anyOf"]]
    assert sorted(b["properties"]["kind"]["const"] for b in branches) == sorted(KINDS)
    assert all(b["additionalProperties"] is False for b in branches)


@pytest.mark.parametrize("config", CONFIGS, ids=lambda p: p.name)
def test_every_shipped_config_names_the_schema_and_follows_it(config):
    text = config.read_text()
    assert text.splitlines()[0] == LINE
    jsonschema.validate(yaml.safe_load(text), json.loads(SHIPPED.read_text()))


def test_an_editor_flags_a_misspelt_key_and_a_value_out_of_range():
    schema = json.loads(SHIPPED.read_text())
    good = yaml.safe_load((ROOT / "configs" / "demo.yaml").read_text())
    for bad in ({**good, "goal": [304]}, {**good, "robot": {"radius": -1.0}}, {**good, "kind": "cats"}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(bad, schema)


def test_the_command_prints_or_writes_the_schema(tmp_path):
    runner = CliRunner()
    r = runner.invoke(app, ["schema"])
    assert r.exit_code == 0 and json.loads(r.stdout)["title"] == "semsearch scenario"
    r = runner.invoke(app, ["schema", "--out", str(tmp_path / "s.json")])
    assert r.exit_code == 0 and (tmp_path / "s.json").read_text() == api.schema_text()
    r = runner.invoke(app, ["schema", "--out", str(tmp_path / "s.txt")])
    assert r.exit_code == 2 and "--out" in r.output


def test_the_shipped_schema_is_the_one_the_models_give():
    """configs/scenario.schema.json is what `semsearch schema` writes (rewrite it with
    `semsearch schema --out configs/scenario.schema.json` after changing a model)."""
    assert SHIPPED.read_text() == api.schema_text()
