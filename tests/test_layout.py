"""The house: no import hides inside a function (the layer contract itself is checked by
lint-imports in CI, from pyproject.toml)."""

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "semsearch_cli"


def test_no_import_inside_a_function():
    found = []
    for f in sorted(PKG.rglob("*.py")):
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for sub in ast.walk(node):
                    if isinstance(sub, (ast.Import, ast.ImportFrom)):
                        found.append(f"{f.relative_to(PKG)}:{sub.lineno}")
    assert found == []


def test_only_tasks_and_report_sections_name_the_kinds():
    """Outside tasks/ (and the report's per-kind sections and the config that reads the kind) no
    module compares against a kind's name."""
    allowed = {"tasks", "report", "config"}
    found = []
    for f in sorted(PKG.rglob("*.py")):
        if f.relative_to(PKG).parts[0] in allowed:
            continue
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Compare):
                names = [c.value for c in [node.left, *node.comparators] if isinstance(c, ast.Constant)]
                if any(n in ("doors", "objects", "chain") for n in names):
                    found.append(f"{f.relative_to(PKG)}:{node.lineno}")
    assert found == []
