"""Every episode can be solved: the check a suite's builders run on each episode they freeze.

An episode of door search is **solvable** from a start heading when

1. the robot's disk fits at the start and the start is joined to the scenario's start through
   cells where it fits (the start cell lies in :attr:`~semsearch_cli.world.ground_truth.World.reach`,
   the 4-connected c-space of the robot radius, on the known map);
2. some reachable cell reads the goal's sign (:meth:`~semsearch_cli.world.ground_truth.World.reading_cells`)
   and the geodesic from the start to one is finite (the episode's shortest path); and
3. the first re-plan has somewhere to go: after the run's first sensing frame at the start pose
   and heading (the laser into the belief, the cameras' reads), and the turn on the spot the
   search makes when it sees no frontier candidate, some frontier candidate, or failing them some
   wall face not yet read (where the search goes when the frontier gives nothing), is reachable
   from the start cell by the belief's own path search. Otherwise every planner ends the run
   ``stuck`` at its start with no decision.

The third condition is what failed on doors-v1 starts drawn 0.5 m from a wall and facing it (the
drawing's clearance): the forward laser then shows a band of known free space no wider than the
robot needs (twice its radius and half a cell) between the wall and the unseen half-plane behind
the robot; the frontier candidates at the band's far ends are not joined to the start through
cells where the robot fits, and since there are candidates the search does not turn on the spot to
look behind it. Measured on two doors-v1 test splits of our own salts: 3 of 1,600 episodes, each
``stuck`` at 0 m for greedy, nsos and bvp alike.

The check is planner-free and deterministic: it senses with the run's own random stream of
repeat ``k`` (:func:`~semsearch_cli.tasks.episodes.episode_seed`); a start whose heading is drawn
at each repeat is checked at the heading of every repeat the suite runs.

A builder draws an unsolvable drawn start again (:func:`solvable_episodes`): a new cell and heading
among the cells the scenario's ``episodes`` section draws from, by the builder's own generator, so
that a split stays reproducible from its salt and only the episodes that failed move. A start given
by hand (the thesis' own) cannot be drawn again: it is an error.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ScenarioError
from ..tasks.doors import DoorSearch, DoorTask
from ..tasks.episodes import Episode, draw_starts, episode_seed

REDRAWS = 100  # draws of a new start for one unsolvable episode before the builder gives up


def _reachable(belief, r: int, c: int, cands) -> bool:
    """Whether a cell of ``cands`` other than (r, c) is reachable from (r, c) by the belief's path
    search (the one a target's path is planned with)."""
    if len(cands) == 0:
        return False
    d = belief.search(r, c, cands.rows, cands.cols, 0).lengths(cands.rows, cands.cols)
    return bool((np.isfinite(d) & ((cands.rows != r) | (cands.cols != c))).any())


def first_plan_has_target(task: DoorTask, ep: Episode, repeat: int = 0) -> bool:
    """Condition 3 of the module docstring for repeat ``repeat`` of ``ep``: the first re-plan of a
    door search from the episode's start has a reachable target (or the first look reads the
    goal)."""
    rng = np.random.default_rng(episode_seed(ep, repeat, task.sc.experiment.base_seed))
    st = task.start_state(ep, rng)
    st.belief = task.new_belief()
    search = DoorSearch(task, None, ep.goal, rng)
    found, _ = search.sense(st)  # the loop's first step: sense, update the belief, re-plan
    search.update(st)
    if found:
        return True
    prep = search.prepare(st)
    if isinstance(prep, str):  # looking round read the goal
        return True
    ctx, cands = prep
    if _reachable(st.belief, ctx.row, ctx.col, cands):
        return True
    cam = task.sc.door_camera
    walls = st.belief.unread_walls(cam.range, np.radians(cam.fov) / 2, search.approach, search.views_needed)
    return _reachable(st.belief, ctx.row, ctx.col, walls)


def why_unsolvable(task: DoorTask, ep: Episode, repeats: int = 1) -> str | None:
    """Why episode ``ep`` of a door task cannot be solved (the module docstring's conditions), or
    None when it can; a start whose heading is drawn per repeat is checked at repeats ``0 ..
    repeats - 1``."""
    w = task.world
    r, c = (int(v) for v in w.frame.to_index(ep.x, ep.y))
    if not (0 <= r < w.frame.height and 0 <= c < w.frame.width and w.reach[r, c]):
        return (f"the robot's disk ({w.radius:g} m) does not fit at the start ({ep.x:g}, {ep.y:g}) m, or the start is not "
                "joined to the scenario's start through cells where it fits")
    if not w.reading_cells(ep.goal).any():
        return f"no cell the robot can reach reads the sign {ep.goal}"
    if not math.isfinite(task.shortest_from(ep.goal, ep.x, ep.y)):
        return f"no path from the start to a cell that reads the sign {ep.goal}"
    for k in range(1 if ep.heading is not None else repeats):
        if not first_plan_has_target(task, ep, k):
            at = f"heading {ep.heading:g} deg" if ep.heading is not None else f"repeat {k}'s heading"
            return (f"from the start ({ep.x:g}, {ep.y:g}) m at {at} the first re-plan has no reachable frontier candidate "
                    "nor wall face to read: every planner ends stuck at the start")
    return None


def unsolvable(task, repeats: int = 1) -> list[tuple[Episode, str]]:
    """The episodes of a task's set that cannot be solved, with why (door search; other kinds
    have none, see :func:`why_unsolvable`)."""
    if not isinstance(task, DoorTask):
        return []
    out = []
    for ep in task.episodes:
        why = why_unsolvable(task, ep, repeats)
        if why is not None:
            out.append((ep, why))
    return out


def solvable_episodes(task, repeats: int, rng: np.random.Generator | None) -> tuple[list[Episode], list[tuple[Episode, Episode]]]:
    """A task's episodes with each unsolvable one drawn again by ``rng`` (see the module
    docstring), and the pairs (old, new) that moved. A :class:`ScenarioError` when an unsolvable
    episode was not drawn (given by hand, shared by every goal, or no ``rng``), or when
    :data:`REDRAWS` draws find no solvable start."""
    eps = list(task.episodes)
    bad = unsolvable(task, repeats)
    if not bad:
        return eps, []
    spec = task.sc.episodes
    drawn = spec is not None and spec.given is None and spec.file is None and not spec.shared
    if not drawn or rng is None:
        ep, why = bad[0]
        raise ScenarioError(task.file, "episodes", f"episode {ep.index} (goal {ep.goal}) cannot be solved: {why}"
                            f"{'' if len(bad) == 1 else f' ({len(bad)} episodes cannot)'}")
    w = task.world
    stand = task.start_cells(spec)
    moved = []
    for ep, why in bad:
        ok = stand.copy()
        for e in eps:  # not another start of the same goal
            if str(e.goal) == str(ep.goal):
                ok[tuple(int(v) for v in w.frame.to_index(e.x, e.y))] = False
        field = task.goal_field(ep.goal)
        try:
            for _ in range(REDRAWS):
                got = draw_starts(ok, [field], w.frame.to_world, 1, rng, spec.min_distance, spec.max_distance)
                if not got:
                    break
                x, y, h = got[0]
                new = Episode(ep.index, ep.goal, x, y, h, None, task.shortest_from(ep.goal, x, y))
                if why_unsolvable(task, new, repeats) is None:
                    break
                ok[tuple(int(v) for v in w.frame.to_index(x, y))] = False
            else:
                got = []
        finally:
            task.forget_field(ep.goal)
        if not got:
            raise ScenarioError(task.file, "episodes", f"episode {ep.index} (goal {ep.goal}) cannot be solved ({why}), "
                                f"and {REDRAWS} starts drawn again could not either")
        eps[ep.index] = new
        moved.append((ep, new))
    return eps, moved


__all__ = ["REDRAWS", "first_plan_has_target", "solvable_episodes", "unsolvable", "why_unsolvable"]
