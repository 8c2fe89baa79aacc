"""What semsearch knows and makes: the scenario schema, ``validate``, ``show``, ``episodes``, the
``planners`` and ``scenarios`` it has, ``init`` and ``planner_spec``."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pandas as pd

from ..config import PlannerSpec, load_scenario, scenario_schema
from ..errors import ScenarioError
from ..planners import PLANNERS, load_entry_points
from ..planners.base import check_params, load_planner_file, parse_entry, path_fields
from ..plugins import load_kinds
from ..report import build as report_build
from ..report.document import atomic_text
from ..runner import Loaded
from ..tasks.episodes import EPISODE_COLUMNS, set_hash
from ..files import output_file, output_folder, temp_path
from .. import shipped
from ..shipped import scenario_file


def schema_text() -> str:
    """The scenario JSON Schema (every kind's model), as ``semsearch schema`` writes it."""
    return json.dumps(scenario_schema(), indent=2) + "\n"


def schema(out: str | Path | None = None) -> Path | None:
    """Write the scenario JSON Schema to ``out`` (.json, atomically); None: return nothing (the
    caller prints :func:`schema_text`). Editors read it through the first line of a scenario,
    ``# yaml-language-server: $schema=PATH``, for completion and checking as you type."""
    if out is None:
        return None
    path = output_file(out, "--out", (".json",))
    atomic_text(path, schema_text())
    return path


def validate(scenario: str | Path) -> dict:
    """Every check of the loader, plus counts, each goal's shortest path from the scenario's start
    and the episode set (no simulation)."""
    task = Loaded.load(scenario_file(scenario)).task
    eps = task.episodes
    sp = [e.shortest_m for e in eps]
    return {**task.describe(), "episodes": f"{len(eps)} over {len({str(e.goal) for e in eps})} goals, shortest paths "
            f"{min(sp):.1f}-{max(sp):.1f} m, set hash {set_hash(eps)} (semsearch episodes writes them)"}


def show(scenario: str | Path, out: str | Path) -> Path:
    """Draw a scenario (map, signs or places, start, goals) to a PNG without simulating."""
    out = output_file(out, "--out", (".png", ".pdf", ".svg"))
    loaded = Loaded.load(scenario_file(scenario))
    return report_build.show(loaded, out)


def episodes(scenario: str | Path, out: str | Path) -> tuple[Path, list, str]:
    """Write a scenario's episode set to the CSV ``out`` (episode, goal, start_x, start_y,
    start_heading, room, shortest_m, hash), atomically; returns (file, episodes, set hash).
    ``episodes: {file: that.csv}`` in a scenario runs exactly that set."""
    loaded = Loaded.load(scenario_file(scenario))
    eps = loaded.task.episodes
    rows = pd.DataFrame([loaded.task.episode_row(e) for e in eps], columns=EPISODE_COLUMNS)
    path = output_file(out, "--out", (".csv",))
    tmp = temp_path(path)
    rows.to_csv(tmp, index=False)
    os.replace(tmp, path)
    return path, eps, set_hash(eps)


_ROLE = re.compile(r":(?:class|func|meth|attr|mod|data|exc|obj):`(~?)([\w.]+)`")


def _plain_doc(text: str) -> str:
    """A docstring's text for a console: Sphinx roles (``:class:`~a.B```) as their plain names
    (``B``), double backquotes as single quotes."""
    text = _ROLE.sub(lambda m: m.group(2).rsplit(".", 1)[-1] if m.group(1) else m.group(2), text)
    return text.replace("``", "'")


def _shown(path: str | Path) -> str:
    """A path as the user would type it: relative to the working folder when it lies inside it."""
    p = Path(path)
    try:
        return p.relative_to(Path.cwd()).as_posix()
    except ValueError:
        return str(p)


def planners(scenario: str | Path | None = None) -> list[dict]:
    """Every planner semsearch can run: built-in, from installed packages (entry points) and,
    with ``scenario``, from the files it names; each with its kind of search (comma-separated
    for one that answers several), where it comes from, its description and its parameters
    (name, type, default, description)."""
    load_kinds()
    load_entry_points()
    own = {}
    if scenario is not None:
        loaded = Loaded.load(scenario_file(scenario))
        own = {v.name: v.module for v in loaded.task.variants() if v.module}
    out = []
    for name, cls in sorted(PLANNERS.items(), key=lambda kv: (kv[1].task, kv[0])):
        mod = cls.__module__
        source = (f"file {_shown(own[name])}" if name in own else "built-in" if mod.startswith("semsearch_cli.")
                  else f"module {mod}")
        if mod.startswith("semsearch_user_planners.") and name not in own:
            continue  # a file some other scenario loaded in this process
        doc = _plain_doc((cls.__doc__ or "").strip().split("\n\n")[0])
        params = [{"name": k, "type": getattr(f.annotation, "__name__", str(f.annotation)),
                   "default": None if f.is_required() else f.default, "description": f.description or ""}
                  for k, f in cls.Params.model_fields.items()]
        out.append({"name": name, "kind": ", ".join(cls.kinds) if cls.kinds else cls.task, "source": source,
                    "description": " ".join(doc.split()), "params": params, "privileged": cls.privileged})
    return out


def scenarios() -> list[dict]:
    """The shipped scenarios (package data): each one's ``name`` (what ``semsearch run NAME``
    takes), ``kind``, ``file`` and ``description`` (:func:`semsearch_cli.shipped.describe`)."""
    out = []
    for name in shipped.names():
        sc = load_scenario(shipped.path(name))
        out.append({"name": name, "kind": sc.kind, "file": shipped.path(name), "description": shipped.describe(name)})
    return out


def init(name: str, folder: str | Path, force: bool = False) -> list[Path]:
    """Copy the shipped scenario ``name`` and the files it names into ``folder``, to edit (see
    :func:`semsearch_cli.shipped.init`); the copy is validated before this returns."""
    written = shipped.init(name, output_folder(folder, "DIR"), force)
    Loaded.load(written[0])
    return written


def planner_spec(text: str, module: str | Path | None = None) -> PlannerSpec:
    """A planner given on the command line, ``NAME`` or ``NAME[key=value,...]`` (as rows label
    it: ``nsos[alpha=0.9]``), registered by ``module`` (a user's Python file) when given. A
    parameter that names a file (the llm planner's ``prompt``, ``replay``) is taken relative to the
    working folder, and written absolute."""
    name, params = parse_entry(text)  # its form, and no key in an address (refused, never shown)
    m = {"name": name}
    if module is not None:  # the file's planners come from it; a built-in (or installed) planner beside them does not
        mod = Path(module)
        if not mod.is_file():
            raise ScenarioError(str(mod), "", "no such planner file (--planner-file)")
        mine = load_planner_file(mod)
        if m["name"] not in mine and m["name"] not in PLANNERS:
            load_entry_points()  # a planner of an installed package, named beside the file's
        if m["name"] in mine or m["name"] not in PLANNERS:
            params["module"] = str(mod.resolve())
    cls = PLANNERS.get(m["name"])
    if cls is not None:  # a parameter its planner refuses, named: 'nsos[alpha=2]': alpha must be at most 1
        try:
            fault = check_params(cls, name, {k: v for k, v in params.items() if k != "module"})
        except (Exception, SystemExit):  # a user's validator that raises: expand_variants names its line
            fault = None
        if fault:
            raise ScenarioError("<command line>", "--planner", fault[1])
    for k in path_fields(cls.Params) if cls is not None else ():  # a file named here is relative to this folder, not the floor's
        if isinstance(params.get(k), str) and not Path(params[k]).is_absolute():
            params[k] = str(Path(params[k]).resolve())
    return PlannerSpec(name=m["name"], **params)
