from .doors import DoorBelief, Candidates

__all__ = ["DoorBelief", "Candidates"]
