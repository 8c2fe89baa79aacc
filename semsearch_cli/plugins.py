"""Kinds of search from other packages.

A package adds a kind of search by declaring a module under the entry-point group
``semsearch.kinds`` (in its pyproject.toml: ``[project.entry-points."semsearch.kinds"]
beacons = "my_package.beacons"``). Importing that module registers what the kind is, with the
registries semsearch's own kinds use: its scenario model (``config.register_kind``), its task
(``tasks.register_task``), its planners (``planners.register_planner``), its report section
(``report.sections.register_section``) and, if it has one, its Gymnasium environment. semsearch
imports every such module once per process, before it reads a scenario, a results folder or its
planner list (:func:`load_kinds`); nothing in semsearch changes. docs/layout.md says which files a
kind needs and why.
"""

from __future__ import annotations

from importlib.metadata import entry_points

from .errors import ScenarioError

GROUP = "semsearch.kinds"
_LOADED: list[str] = []  # the entry points imported in this process


def load_kinds() -> list[str]:
    """Import every module registered under :data:`GROUP` (once per process); returns their
    entry points' names. A module that fails to import is a :class:`ScenarioError` naming it."""
    if _LOADED:
        return _LOADED[1:]
    _LOADED.append("")  # before importing: a kind's module that reads a scenario does not load itself again
    for ep in entry_points(group=GROUP):
        try:
            ep.load()
        except ScenarioError:
            raise
        except Exception as exc:
            raise ScenarioError(f"entry point {ep.name} = {ep.value}", GROUP,
                                f"the kind's package failed to load: {type(exc).__name__}: {exc}") from None
        _LOADED.append(ep.name)
    return _LOADED[1:]
