"""A finished run -> one flat row (SPEC 9)."""

from __future__ import annotations

import json

COLUMNS = ["scenario", "planner", "params", "goal", "seed", "outcome", "success", "distance_m", "shortest_m",
           "ratio", "spl", "steps", "decisions", "navigator", "wall_s"]


def run_row(scenario: str, variant, goal, seed: int, result, shortest: float, navigator: str) -> dict:
    """SPL (Anderson et al. 2018): success * shortest / max(shortest, distance)."""
    success = result.outcome == "found"
    d = result.distance_m
    return {
        "scenario": scenario,
        "planner": variant.label,
        "params": json.dumps(dict(variant.params), sort_keys=True),
        "goal": goal,
        "seed": seed,
        "outcome": result.outcome,
        "success": int(success),
        "distance_m": round(d, 3),
        "shortest_m": round(shortest, 3),
        "ratio": round(d / shortest, 4) if shortest > 0 else float("nan"),
        "spl": round(shortest / max(shortest, d), 4) if success and shortest > 0 else 0.0,
        "steps": result.steps,
        "decisions": result.decisions,
        "navigator": navigator,
        "wall_s": round(result.wall_s, 3),
    }
