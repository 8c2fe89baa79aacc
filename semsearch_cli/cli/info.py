"""What semsearch knows and makes: ``validate``, ``scenarios``, ``init``, ``schema``, ``show``,
``version``, ``episodes`` and ``planners``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import typer
from rich.table import Table

from .. import api
from ..provenance import version_line
from ..errors import ScenarioError
from .common import SCENARIO, _fail, _path, app, out


@app.command()
def validate(scenario: Path = SCENARIO):
    """Check a scenario without simulating: every loader check, sign counts, shortest paths."""

    try:
        info = api.validate(scenario)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"{scenario}: ok")
    for k, v in info.items():
        out.print(f"  {k}: {v}")


@app.command()
def scenarios():
    """List the shipped scenarios: `semsearch run NAME` runs one from any folder, and `semsearch
    init NAME DIR` copies one (with its map) to edit."""

    t = Table(title="shipped scenarios (semsearch run NAME; semsearch init NAME DIR to edit a copy)")
    for col in ("name", "kind", "description"):
        t.add_column(col, overflow="fold")
    for s in api.scenarios():
        t.add_row(s["name"], s["kind"], s["description"])
    out.print(t)


@app.command()
def init(
    name: str = typer.Argument(..., help="A shipped scenario's name (semsearch scenarios)."),
    folder: str = typer.Argument(..., callback=_path, help="Folder to copy it into (created if needed)."),
    force: bool = typer.Option(False, "--force", help="Overwrite files of the same names in the folder."),
):
    """Copy a shipped scenario and the files it names (map, signs, the JSON Schema) into a folder
    of yours, with its paths rewritten to the copies, to edit and run."""

    try:
        written = api.init(name, folder, force)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {written[0]} and {len(written) - 1} file(s) it names; run it with: semsearch run {written[0]}")


@app.command()
def schema(out_file: Optional[str] = typer.Option(None, "--out", callback=_path, help="JSON file to write (default: print it).")):
    """The scenario format as a JSON Schema: every field of every kind of search, with its type,
    default, bounds and description. Point an editor at it with a scenario's first line,
    `# yaml-language-server: $schema=scenario.schema.json`, for completion and checking."""

    try:
        path = api.schema(out_file)
    except ScenarioError as exc:
        _fail(exc)
    if path is None:
        sys.stdout.write(api.schema_text())
    else:
        out.print(f"wrote {path}")


@app.command()
def show(
    scenario: Path = SCENARIO,
    out_file: str = typer.Option("map.png", "--out", callback=_path, help="Image to write: .png, .pdf or .svg."),
):
    """Draw a scenario: the map with every sign and its number, the start and the goals."""

    try:
        path = api.show(scenario, out_file)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {path}")


@app.command()
def version():
    """Print the semsearch version, the hash of its code and the git commit it runs from."""
    out.print(version_line())


@app.command()
def episodes(
    scenario: Path = SCENARIO,
    out_file: str = typer.Option("episodes.csv", "--out", callback=_path, help="CSV to write."),
):
    """Write a scenario's episode set (each start and goal, its shortest path and a content hash)
    to a CSV, to freeze, share or name it: `episodes: {file: episodes.csv}` in a scenario runs it."""

    try:
        path, eps, h = api.episodes(scenario, out_file)
    except ScenarioError as exc:
        _fail(exc)
    goals = len({str(e.goal) for e in eps})
    out.print(f"wrote {path}: {len(eps)} episodes over {goals} goals, set hash {h}")


@app.command("planners")
def planners_cmd(scenario: Optional[Path] = typer.Argument(None, help="Also list the planners this scenario's files register.")):
    """List every planner (built-in, from installed packages, and a scenario's own files) with its
    kind of search, where it comes from, its parameters, their defaults and descriptions."""

    try:
        found = api.planners(scenario)
    except ScenarioError as exc:
        _fail(exc)
    t = Table(title="planners (parameters: name = default, description)")
    widest = max((len(p["source"]) for p in found), default=0)
    for col in ("name", "kind", "source", "description", "parameters"):
        # a planner file's path is printed whole where it fits (a folded path cannot be copied)
        t.add_column(col, overflow="fold", min_width=min(widest, 80) if col == "source" else None)
    for p in found:
        params = "\n".join(f"{q['name']} = {q['default']!r}" + (f": {q['description']}" if q["description"] else "")
                           for q in p["params"]) or "none"
        kind = p["kind"] + (f"\nprivileged: told {p['privileged']}" if p["privileged"] else "")  # a reference, not a competitor
        t.add_row(p["name"], kind, p["source"], p["description"], params)
    out.print(t)
