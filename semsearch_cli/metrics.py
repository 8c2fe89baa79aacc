"""A finished run -> one flat row."""

from __future__ import annotations

import json
import math

import pandas as pd

from .errors import UNAVAILABLE
from .planners.base import COST_COLUMNS  # noqa: F401  (the rows' cost columns, read with the others from here)

# the columns of runs.csv as 0.2.0 wrote them (and ``engine``, the simulator engine that made the row,
# from 0.3.0; a row without it was made by engine 1: semsearch_cli.engine), for every kind: the ones every kind writes, and the
# built-in kinds' own (room and time_s: indirect search; stage and map: chains), each in its place.
# A runs.csv holds all of them through 0.2.x; a kind's columns beyond these (a kind from another
# package, Task.columns) follow them, in the folders of that kind (columns_for).
COLUMNS = ["kind", "scenario", "planner", "params", "goal", "episode", "seed", "start_x", "start_y", "start_heading",
           "room", "stage", "map", "outcome", "cause", "success", "distance_m", "shortest_m", "ratio", "spl", "soft_spl",
           "left_m", "time_s", "steps", "decisions", "navigator", "wall_s", "message", "fingerprint", "code", "engine"]
BUILT_IN_KIND_COLUMNS = ("room", "stage", "map", "time_s")
SHARED = [c for c in COLUMNS if c not in BUILT_IN_KIND_COLUMNS]  # what every kind's run row holds (run_row)
# what a semsearch-bench run adds to each row (semsearch bench run): the suite, its split and that
# split's hash, the numbering its labels were run under, the floor (a folder of the split), and the
# SHA-256 of the run's decisions file (decisions/<run>.json: the record that replays it)
BENCH_COLUMNS = ("suite", "split", "suite_hash", "numbering", "floor", "decisions_sha256")
# what a planner that pays for its decisions reports on each row: planners.base.COST_COLUMNS
# what a privileged planner was told that a robot is not (Planner.privileged; "" on every other
# planner's row): a folder that ran one has the column (a reference, never a competitor)
PRIVILEGED = "privileged"


def columns_for(kind_columns) -> list[str]:
    """The columns of a runs.csv whose runs are of kinds with these own columns: :data:`COLUMNS`,
    then the kinds' columns it lacks, before the provenance columns (navigator onwards)."""
    extra = [c for c in dict.fromkeys(kind_columns) if c not in COLUMNS]
    k = COLUMNS.index("navigator")
    return COLUMNS[:k] + extra + COLUMNS[k:]

def outside_the_run(rows: pd.DataFrame) -> pd.Series:
    """Which rows are of runs that could not run for a cause outside them (outcome ``error``, a
    message starting with :data:`~semsearch_cli.errors.UNAVAILABLE`): no result, run again on
    resume, left out of a board's statistics."""
    if not len(rows):
        return pd.Series(False, index=rows.index, dtype=bool)
    return (rows["outcome"].astype(str) == "error") & rows["message"].astype(str).str.startswith(UNAVAILABLE)


FALLBACK_FLAG = 0.05  # a share of a planner's decisions fallen back above this is marked (the bench board, docs/bench-board.md)


def fallback_shares(rows) -> list[tuple[str, int, int]]:
    """Per planner whose rows count fallbacks (a language model's: the ``fallbacks`` cost
    column), in the rows' order: (label, decisions that fell back, decisions asked). A decision
    ends in one valid reply or in the fallback, so the decisions asked are ``llm_calls -
    invalid_replies + fallbacks`` (a decision cut short by the run's budget is not counted). A
    chain's stage rows repeat their run's costs: only a run's own row counts."""
    if not len(rows) or "fallbacks" not in rows.columns:
        return []
    if "stage" in rows.columns:
        rows = rows[rows["stage"].fillna("").astype(str) == ""]
    out = []
    for label, g in rows.groupby("planner", sort=False):
        f = pd.to_numeric(g["fallbacks"], errors="coerce")
        if not f.notna().any():
            continue
        valid = pd.to_numeric(g["llm_calls"], errors="coerce") - pd.to_numeric(g["invalid_replies"], errors="coerce")
        n = int(f.sum())
        out.append((str(label), n, int(valid.sum()) + n))
    return out


# the failure cause of each outcome (empty for a run that found its goal)
CAUSES = {"found": "", "not_found": "explored", "stuck": "stuck", "budget": "budget", "error": "error",
          "timeout": "timeout"}


def spl(success: bool, shortest: float, distance: float) -> float:
    """Success weighted by path length (Anderson et al. 2018) of one run:
    ``success * shortest / max(shortest, distance)``; 0 when the shortest path is not positive."""
    return shortest / max(shortest, distance) if success and shortest > 0 else 0.0


def soft_spl(shortest: float, distance: float, left: float) -> float:
    """SoftSPL (Datta et al. 2020) of one run: ``(1 - left / shortest) * shortest / max(shortest,
    distance)``, the progress made towards the goal (``left``: the geodesic distance left where the
    run ended, 0 when it succeeded) weighted by path length; the progress term is clipped at 0 (a
    run that ends farther than it started made none). NaN when ``left`` is unknown."""
    if not shortest > 0:
        return 1.0 if left == 0 else 0.0
    if not left == left:
        return float("nan")
    progress = max(0.0, 1.0 - (left if math.isfinite(left) else shortest) / shortest)
    return progress * shortest / max(shortest, distance)


def result_columns(outcome: str, distance: float, shortest: float, steps: int, decisions: int, wall_s: float) -> dict:
    """The columns that say how a run (or a chain's stage) went: outcome, cause, success, distance
    beside the shortest path (m), ratio, SPL, counts and wall time; the one place they are made."""
    success = outcome == "found"
    return {"outcome": outcome, "cause": CAUSES.get(outcome, outcome), "success": int(success),
            "distance_m": round(distance, 3), "shortest_m": round(shortest, 3),
            "ratio": round(distance / shortest, 4) if shortest > 0 else float("nan"),
            "spl": round(spl(success, shortest, distance), 4), "steps": steps, "decisions": decisions,
            "wall_s": round(wall_s, 3)}


def run_row(kind: str, scenario: str, variant, ep, seed: int, result, navigator: str) -> dict:
    """One row's :data:`SHARED` columns, what every kind writes: the run's identity (kind,
    scenario, planner label and parameters, goal, episode, repeat and start), its outcome and, when
    it failed, why (``cause``: budget, stuck, explored (nowhere left to look), error), its distance
    beside the episode's shortest path, SPL, SoftSPL, the distance left to the goal (empty when the
    kind does not know it), and counts. A kind adds its own columns (``Task.record``: indirect
    search its room and simulated time; chains their stage rows); a column a row lacks is written
    empty."""
    success = result.outcome == "found"
    d = result.distance_m
    shortest = ep.shortest_m
    left = result.left_m
    return {
        "kind": kind,
        "scenario": scenario,
        "planner": variant.label,
        "params": json.dumps(dict(variant.params), sort_keys=True),
        "goal": ep.goal,
        "episode": ep.index,
        "seed": seed,
        "start_x": round(ep.x, 4),
        "start_y": round(ep.y, 4),
        "start_heading": round(math.degrees(result.start_heading), 3) if result.start_heading == result.start_heading else "",
        **result_columns(result.outcome, d, shortest, result.steps, result.decisions, result.wall_s),
        "soft_spl": round(soft_spl(shortest, d, 0.0 if success else left), 4) if d == d else float("nan"),
        "left_m": round(left, 3) if left == left else "",
        "navigator": navigator,
        "message": result.message,
    }
