"""A front end of your own in 40 lines: open an episode, show each decision, take an answer.

Any driver (a web viewer, a notebook widget, another robot middleware) runs an episode this way:
``Task.open`` gives the batch's own run, the same start, generator and search, with whoever you
like in the planner's seat. Here the "user" is a function that picks the frontier target nearest
the robot; give your own ``pick`` to ask a person.   python examples/front_end.py [scenario] [goal]
"""

import sys

import numpy as np

from semsearch_cli.planners import Decision
from semsearch_cli.runner import Loaded
from semsearch_cli.shipped import scenario_file
from semsearch_cli.tasks.decisions import Agent, DecisionPoint


def nearest(ctx, cands) -> Decision | None:
    """The user's answer: the candidate nearest the robot (None: look at the nearest unread wall)."""
    if len(cands) == 0:
        return None
    k = int(np.argmin(np.hypot(cands.rows - ctx.row, cands.cols - ctx.col)))
    return Decision(int(cands.rows[k]), int(cands.cols[k]))


def main(scenario: str = "demo", goal: str = "304", pick=nearest, show=print) -> dict:
    task = Loaded.load(scenario_file(scenario)).task  # a file, or a shipped scenario's name
    episode = task.as_episode(goal)
    run = task.open(None, episode, seed=0, seat=Agent("user", replan_on_signs=True))
    point = run.start()
    while isinstance(point, DecisionPoint):  # the run waits here until it is answered
        ctx, cands = point.observation, point.choices
        show(f"at ({ctx.x:.1f}, {ctx.y:.1f}) m, {run.state.distance:.1f} m so far: {len(cands)} frontier targets")
        point = run.answer(pick(ctx, cands))
    row = run.rows()[0]
    show(f"{row['outcome']} after {row['distance_m']} m (shortest {row['shortest_m']} m), {row['decisions']} decisions")
    return row


if __name__ == "__main__":
    main(*sys.argv[1:3])
