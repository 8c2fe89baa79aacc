"""Learning door planners from what the known map says (issue 39): labels computed on the
ground truth for each frontier target of each decision, beside the features the robot has. See
:mod:`.labels` and :mod:`.floors` (training floors disjoint from the benchmark's)."""

from .floors import benchmark_seeds, training_floor
from .labels import FEATURES, LabelSeat, collect, oracle_costs

__all__ = ["FEATURES", "LabelSeat", "benchmark_seeds", "collect", "oracle_costs", "training_floor"]
