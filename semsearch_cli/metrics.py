"""A finished run -> one flat row (SPEC 9)."""

from __future__ import annotations

import json

COLUMNS = ["kind", "scenario", "planner", "params", "goal", "seed", "stage", "map", "outcome", "success", "distance_m",
           "shortest_m", "ratio", "spl", "time_s", "steps", "decisions", "navigator", "wall_s", "message", "fingerprint"]


def spl(success: bool, shortest: float, distance: float) -> float:
    """Success weighted by path length (Anderson et al. 2018) of one run:
    ``success * shortest / max(shortest, distance)``; 0 when the shortest path is not positive."""
    return shortest / max(shortest, distance) if success and shortest > 0 else 0.0


def run_row(kind: str, scenario: str, variant, goal, seed: int, result, shortest: float, navigator: str) -> dict:
    """One row: the run's identity (kind, scenario, planner label and parameters, goal, seed), its
    outcome and distance beside the shortest path, SPL and counts. ``stage`` and ``map`` are
    empty here; per-stage rows of chains fill them. ``time_s`` is the simulated time of a task
    with a clock (indirect search), empty for the others."""
    success = result.outcome == "found"
    d = result.distance_m
    return {
        "kind": kind,
        "scenario": scenario,
        "planner": variant.label,
        "params": json.dumps(dict(variant.params), sort_keys=True),
        "goal": goal,
        "seed": seed,
        "stage": "",
        "map": "",
        "outcome": result.outcome,
        "success": int(success),
        "distance_m": round(d, 3),
        "shortest_m": round(shortest, 3),
        "ratio": round(d / shortest, 4) if shortest > 0 else float("nan"),
        "spl": round(spl(success, shortest, d), 4),
        "time_s": round(result.time_s, 2) if result.time_s == result.time_s else "",
        "steps": result.steps,
        "decisions": result.decisions,
        "navigator": navigator,
        "wall_s": round(result.wall_s, 3),
        "message": result.message,
    }
