"""The robot's state between and during episodes: what every kind's search and the step loop
read and change (below :mod:`.loop` and :mod:`.base`, which both use it)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass
class RobotState:
    """The robot between and during episodes.

    x, y : float, m; heading : float, rad; belief : the map and sign reads built so far (door
    search), or None; clock : float, hour of day, or None; distance : float, m travelled so far;
    steps : int; trail : list of (x, y) m, every pose so far; headings : list of rad, the heading
    at every pose (the robot-orientation histogram of nsos); read_signs : sign index -> its label
    as last read, for every sign read at least once.
    """

    x: float
    y: float
    heading: float
    belief: Any = None
    clock: float | None = None
    distance: float = 0.0
    steps: int = 0
    trail: list = field(default_factory=list)
    headings: list = field(default_factory=list)
    read_signs: dict = field(default_factory=dict)
