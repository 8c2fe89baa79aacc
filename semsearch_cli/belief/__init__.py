from .doors import Belief, Candidates

__all__ = ["Belief", "Candidates"]
