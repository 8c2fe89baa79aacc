from .. import deprecation
from .doors import DoorBelief, Candidates

__all__ = ["DoorBelief", "Candidates"]

DEPRECATED = {"Belief": ("semsearch_cli.belief.DoorBelief", DoorBelief)}  # 0.2.0 -> removed in 0.3.0


def __getattr__(name: str):
    return deprecation.alias(__name__, name, DEPRECATED)
