"""Navigation: navigators on the belief (geodesic, harmonic), paths on a known map, and
motion along a path."""

from .known import KnownMap
from .motion import advance
from .navigators import NAVIGATORS, GeodesicNavigator, HarmonicNavigator, Navigator, register_navigator

__all__ = ["NAVIGATORS", "GeodesicNavigator", "HarmonicNavigator", "KnownMap", "Navigator", "advance", "register_navigator"]
