"""Planners: importing this package registers the built-in ones."""

from . import bvp, greedy, nsos  # noqa: F401  (registration side effect)
from .base import PLANNERS, Decision, PlanContext, Planner, Variant, expand_variants, register_planner

from ..objects import search as _object_planners  # noqa: F401,E402  (lsos, brute_force, last_seen)

__all__ = ["PLANNERS", "Decision", "PlanContext", "Planner", "Variant", "expand_variants", "register_planner"]
