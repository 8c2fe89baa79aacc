"""Door-search planners (thesis ch. 4): greedy, nsos and geometric, bvp, and the draft paper's planner."""
