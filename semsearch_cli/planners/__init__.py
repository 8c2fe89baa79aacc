"""Planners: the protocol, the registry and the built-in planners (importing this package
registers them).

The public API for planner authors: :class:`DoorPlanner`, :class:`Decision`, :class:`DoorContext`
and :func:`register_planner` (door search), :class:`ObjectPlanner` and :class:`ObjectContext`
(object search), :class:`IndirectPlanner`, :class:`IndirectContext` and :class:`Goal` (indirect
search).
"""

from .base import (PLANNERS, Decision, DoorContext, DoorPlanner, NoParams, Planner, Told, Variant, code_of, expand_variants,
                   load_entry_points, load_planner_file, planner_class, register_planner)
from .doors import advantage, bvp, draft, greedy, learned, nsos, numbering, oracle, walls  # noqa: F401  (registration side effect)
from . import llm  # noqa: F401  (registers llm)
from .indirect import Goal, IndirectContext, IndirectPlanner
from .objects import ObjectContext, ObjectPlanner, LsosParams, lsos_goals

__all__ = ["PLANNERS", "Decision", "DoorContext", "DoorPlanner", "Goal", "IndirectContext", "IndirectPlanner", "LsosParams", "NoParams", "ObjectContext", "ObjectPlanner", "Planner",
           "Told", "Variant", "code_of", "expand_variants", "load_entry_points", "load_planner_file", "lsos_goals", "planner_class", "register_planner"]
