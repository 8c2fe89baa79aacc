"""The documentation pages generated from the code are current: the scenario format (from the
models' schema), the planners (from the registry) and the schema the configs name. Regenerate
them with `python scripts/make_docs.py`."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import make_docs  # noqa: E402


@pytest.mark.parametrize("page", sorted(make_docs.PAGES))
def test_the_generated_page_is_current(page):
    assert (ROOT / page).read_text() == make_docs.PAGES[page](), f"run python scripts/make_docs.py ({page} is stale)"


def test_every_registered_planner_and_kind_has_its_section():
    text = (ROOT / "docs" / "reference" / "planners.md").read_text()
    for name, cls in make_docs.PLANNERS.items():
        if cls.__module__.startswith("semsearch_cli."):
            assert f"\n### {name}\n" in text
    fmt = (ROOT / "docs" / "reference" / "scenario-format.md").read_text()
    assert all(f"\n## {kind}\n" in fmt for kind in make_docs.KINDS)


def test_the_worked_example_on_the_planner_page_is_the_shipped_file():
    page = (ROOT / "docs" / "planners.md").read_text()
    for f in ("my_planner.py", "scenario.yaml"):
        assert (ROOT / "examples" / "custom_planner" / f).read_text() in page, f


def test_the_observer_example_on_the_planner_page_runs(capsys, monkeypatch):
    page = (ROOT / "docs" / "planners.md").read_text()
    code = page.split("## Watching a run", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(ROOT)
    exec(compile(code, "planners.md", "exec"), {})
    outcome, _, n, _ = capsys.readouterr().out.split(maxsplit=3)
    assert outcome == "found" and int(n) > 0
