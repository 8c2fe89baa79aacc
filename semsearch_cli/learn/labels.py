"""Labels from the known map, and the features the robot has, for every frontier target of every
door decision: the data a learned planner is trained on.

The label of target ``c`` at a decision is the true remaining travel through it, the oracle the
robot does not have: ``oracle_m(c) = d(c) + G(c)``, with ``d(c)`` the metres the robot would drive
to ``c`` on the map it has built (the skeleton path every door planner is given,
:meth:`~semsearch_cli.belief.DoorBelief.search`) and ``G(c)`` the ground-truth geodesic metres
from ``c`` to the nearest pose that reads the goal's sign
(:meth:`~semsearch_cli.tasks.base.Task.goal_field`, with the robot's clearance). The target of
least ``oracle_m`` is what a clairvoyant planner that still has to drive to a frontier target
would choose (``best``). An unreachable target has no label (inf).

The features are what the robot has at that decision, exactly as the ``learned`` planner computes
them (:func:`~semsearch_cli.planners.doors.learned.decision_features`): the target's path length
and its rank among the targets, how many targets there are, the metres travelled and the signs
counted so far, nsos's terms for the target (Eqs. 4.9-4.14 and paper Eq. 16: growing direction,
parity, door and robot orientation, closeness; :mod:`~semsearch_cli.planners.doors.nsos`), the
numbering model's probability that the goal lies beyond the target, metres past it and expected
travel (:mod:`~semsearch_cli.planners.doors.numbering`), and the path, nsos's phi, SF and phi_g
and the expected travel against the decision's best.

:class:`LabelSeat` is the batch's seat that writes one row per target before the run's planner
answers (the behaviour policy: the run is exactly the run that planner makes alone; a test checks
it); :func:`collect` runs a scenario's episodes and repeats with it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..planners import DoorPlanner, Variant
from ..planners.doors.learned import FEATURES, decision_features
from ..planners.doors.nsos import NSOS, NSOSParams
from ..runner import Loaded
from ..tasks.decisions import Seat

ID = ("scenario", "goal", "episode", "seed", "decision", "target", "row", "col")


def oracle_costs(field: np.ndarray, d_m: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``d(c) + G(c)`` (m) per target: ``d_m`` the path to each target on the robot's map (inf when
    unreachable), ``field`` the ground-truth distance field to the goal (m, inf where the goal
    cannot be reached), ``rows``, ``cols`` the targets' cells."""
    g = np.asarray(field, float)[np.asarray(rows, np.int64), np.asarray(cols, np.int64)]
    return np.asarray(d_m, float) + g


class LabelSeat(Seat):
    """The batch's seat that, at each door decision, writes the features and labels of every
    frontier target (:attr:`rows`), then lets the run's planner answer. The nsos terms come from
    an nsos planner of its own (``nsos``: its parameters) run on a copy of the decision whose
    random generator is not the run's, before the run's planner: the run is the planner's own."""

    def __init__(self, task, nsos: NSOSParams = NSOSParams()):
        super().__init__()
        self.task, self.nsos_params = task, nsos
        self.rows: list[dict] = []
        self._nsos: NSOS | None = None
        self._k = 0

    def planner(self, variant):
        self._nsos, self._k = NSOS(self.nsos_params), 0  # one per run, as the batch builds each planner
        return super().planner(variant)

    def decide(self, point):
        if point.kind == DoorPlanner.task and len(point.choices):  # a door decision (the kind door planners answer)
            self._label(point.observation, point.choices)
        return point.ask()

    def _label(self, ctx, cands) -> None:
        X, d = decision_features(ctx, cands, self._nsos)  # what the learned planner sees, exactly
        label = oracle_costs(self.task.goal_field(ctx.goal), d, cands.rows, cands.cols)
        finite = np.isfinite(label)
        best = label == label[finite].min() if finite.any() else np.zeros(len(cands), bool)
        run = self.run
        for i in range(len(cands)):
            row = {"scenario": run.get("scenario"), "goal": run.get("goal"), "episode": run.get("episode"),
                   "seed": run.get("seed"), "decision": self._k, "target": i, "row": int(cands.rows[i]),
                   "col": int(cands.cols[i])}
            row.update(zip(FEATURES, X[i].tolist()))
            row["d_m"] = float(d[i])  # inf when unreachable (the feature is NaN)
            row.update({"oracle_m": float(label[i]), "best": bool(best[i])})
            self.rows.append(row)
        self._k += 1


def collect(scenario: str | Path, planner: str = "greedy", seeds: int = 1, goals=None) -> pd.DataFrame:
    """The labelled targets of every decision of ``planner`` (the behaviour policy, with its
    defaults) over a door scenario's episodes (of ``goals``, when given) and ``seeds`` repeats:
    one row per target (:data:`ID`: the run, the decision, the target's number and cell;
    :data:`FEATURES`; ``oracle_m``; ``best``; and the run's ``outcome``)."""
    loaded = Loaded.load(Path(scenario))
    task = loaded.task
    keep = None if goals is None else {str(g) for g in goals}
    out = []
    for ep in task.episodes:
        if keep is not None and str(ep.goal) not in keep:
            continue
        for seed in range(seeds):
            seat = LabelSeat(task)
            res = task.run(Variant(planner, ()), ep, seed, seat=seat)
            out += [{**r, "outcome": res.outcome} for r in seat.rows]
    return pd.DataFrame(out, columns=[*ID, *FEATURES, "oracle_m", "best", "outcome"])
