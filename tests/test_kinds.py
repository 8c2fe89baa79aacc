"""Each kind of search is declared once per layer: the scenario model (config), the task, the
planners that answer it and the report section. These tests keep the layers agreeing and the
registries strict."""

from typing import Literal

import pytest
import yaml

from semsearch_cli.config import KINDS, OnMap, Scenario, kind_of, parse_scenario, register_kind
from semsearch_cli.errors import ScenarioError
from semsearch_cli.metrics import BUILT_IN_KIND_COLUMNS, COLUMNS, SHARED
from semsearch_cli.planners import PLANNERS, DoorPlanner, Planner, Variant, register_planner
from semsearch_cli.report import build  # noqa: F401  (registers every kind's report section)
from semsearch_cli.report.sections import SECTIONS, Section, register_section
from semsearch_cli.runner import Loaded
from semsearch_cli.tasks import TASKS, Task, register_task


def test_config_tasks_planners_and_report_know_the_same_kinds():
    assert list(KINDS) and set(KINDS) == set(TASKS) == set(SECTIONS)
    planner_kinds = {cls.task for cls in PLANNERS.values() if cls.__module__.startswith("semsearch_cli.")}
    assert {t.planner_kind for t in TASKS.values()} == planner_kinds  # every planner kind has a task, and back
    for kind, task in TASKS.items():
        assert task.kind == kind and task.noun, kind
        assert KINDS[kind].model_fields["kind"].default == kind
        assert KINDS[kind].section in KINDS[kind].model_fields


@pytest.mark.parametrize("kind", sorted(TASKS))
def test_each_kinds_example_is_a_scenario_of_that_kind(kind, tmp_path):
    planner = next(n for n, c in sorted(PLANNERS.items()) if c.task == TASKS[kind].planner_kind)
    path = TASKS[kind].example(tmp_path, planner)
    doc = yaml.safe_load(path.read_text())
    assert "kind" not in doc and kind_of(doc) == kind  # the kind follows from the section given
    assert parse_scenario(doc, path).kind == kind


def test_a_section_of_another_kind_is_named_in_the_error(tmp_path):
    doc = {"name": "x", "map": {"image": "m.png", "resolution": 0.1}, "start": {"x": 1, "y": 1}, "goals": [1],
           "indirect": {}}
    doc["kind"] = "doors"
    with pytest.raises(ScenarioError, match="a doors scenario does not take indirect; remove it"):
        parse_scenario(doc, "s.yaml")
    with pytest.raises(ScenarioError, match="give door numbers under goals"):
        parse_scenario({"name": "x", "map": {"image": "m.png", "resolution": 0.1}, "start": {"x": 1, "y": 1}}, "s.yaml")
    with pytest.raises(ScenarioError, match="unknown kind 'cats'"):
        parse_scenario({"name": "x", "kind": "cats"}, "s.yaml")


def test_the_registries_refuse_duplicates_and_wrong_base_classes():
    with pytest.raises(ValueError, match="already registered"):
        register_kind("doors")(type("Again", (OnMap,), {"section": "map", "__annotations__": {"kind": Literal["doors"]}}))
    with pytest.raises(TypeError):
        register_kind("cats")(dict)
    with pytest.raises(TypeError, match="section"):
        register_kind("cats")(type("NoSection", (Scenario,), {"__annotations__": {"kind": Literal["cats"]}}))
    with pytest.raises(ValueError, match="already registered"):
        register_task(type("Again", (Task,), {"kind": "doors"}))
    with pytest.raises(TypeError):
        register_task(dict)
    with pytest.raises(ValueError, match="already registered"):
        register_planner("greedy")(type("Again", (DoorPlanner,), {}))
    with pytest.raises(TypeError, match="subclass DoorPlanner"):
        register_planner("no-kind")(type("NoKind", (Planner,), {}))
    with pytest.raises(TypeError, match="not a subclass of Planner"):
        register_planner("not-a-planner")(dict)
    with pytest.raises(ValueError, match="already registered"):
        register_section(Section("doors", print, print, print))
    with pytest.raises(TypeError):
        register_section({"kind": "cats"})
    assert "cats" not in KINDS and "not-a-planner" not in PLANNERS and "no-kind" not in PLANNERS


def test_the_shared_columns_and_the_kinds_own_add_up_to_the_rows(tmp_path):
    """metrics.SHARED is what run_row writes (the batch adds fingerprint and code), and the 0.2.0
    columns beyond it are exactly the built-in kinds' own (Task.columns)."""
    own = {c for t in TASKS.values() if t.__module__.startswith("semsearch_cli.") for c in t.columns}
    assert own == set(BUILT_IN_KIND_COLUMNS) and set(SHARED) | own == set(COLUMNS)
    loaded = Loaded.load(TASKS["doors"].example(tmp_path / "d", "greedy"))
    rows = loaded.task.rows(Variant("greedy", ()), loaded.task.episodes[0], 0,
                            loaded.task.run(Variant("greedy", ()), loaded.task.episodes[0], 0))
    assert set(rows[0]) == set(SHARED) - {"fingerprint", "code", "engine"}  # stamped by the batch
