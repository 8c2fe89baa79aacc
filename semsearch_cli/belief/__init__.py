from .. import deprecation
from . import doors
from .doors import DoorBelief, Candidates

__all__ = ["DoorBelief", "Candidates"]

DEPRECATED = doors.DEPRECATED  # Belief (0.2.0 -> removed in 0.3.0)


def __getattr__(name: str):
    return deprecation.alias(__name__, name, DEPRECATED)
