from .belief import Belief, Candidates

__all__ = ["Belief", "Candidates"]
